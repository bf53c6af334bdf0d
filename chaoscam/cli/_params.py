"""``chaoscam params``: every model parameter and numerics setting, its unit, default and range."""

from __future__ import annotations

import argparse


def register(sub) -> None:
    p = sub.add_parser(
        "params",
        help="list every model parameter and numerics setting (--set NAME=VALUE)",
        description="List the fields of chaoscam.Params (the model: Table 1 of the paper and "
        "our decisions) and chaoscam.Numerics (the integrator), each with its unit, default, "
        "allowed range and meaning: what --set NAME=VALUE accepts.",
    )
    p.add_argument("names", nargs="*", metavar="NAME", help="only these fields")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import textwrap

    from .._util import ParameterError, field_table, unknown_message
    from ..model import Params
    from ..numerics import Numerics

    groups = (("model (chaoscam.Params)", Params), ("numerics (chaoscam.Numerics)", Numerics))
    rows = {r["name"]: (title, r) for title, cls in groups for r in field_table(cls)}
    unknown = [n for n in args.names if n not in rows]
    if unknown:
        raise ParameterError(unknown_message(unknown[0], tuple(rows), "field"))
    shown, heading = args.names or list(rows), None
    for name in shown:
        title, r = rows[name]
        if title != heading:
            print(f"{'' if heading is None else chr(10)}{title}")
            heading = title
        print(f"  {name} [{r['unit']}] = {r['default']!r}, in {r['range']}")
        print(textwrap.fill(r["doc"], 96, initial_indent="      ", subsequent_indent="      "))
    return 0
