"""Records of how a result was made that cannot be changed: :class:`FrozenDict` reads like a dict
(``json.dumps``, ``{**d}``, pickling) and refuses every change with a TypeError saying how to
make a changed copy; :func:`freeze_fields` does the same for a frozen result's fields (arrays as
read-only views). Standard library only."""

from __future__ import annotations

__all__ = ["FrozenDict", "freeze_fields"]


class FrozenDict(dict):
    """A read-only dict, its nested dicts too (a nested ``config["base"]["omega"]`` would change
    what a replay simulates); ``{**d, key: value}`` or ``dict(d)`` gives a changeable copy (one
    level: copy a nested record the same way)."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        for key, value in dict.items(self):
            dict.__setitem__(self, key, _frozen(value))

    def _refuse(self, *args, **kwargs):
        raise TypeError(
            "this record is read-only (it says how the result was made); copy it to change "
            "it: {**record, key: value}"
        )

    __setitem__ = __delitem__ = __ior__ = _refuse
    clear = pop = popitem = setdefault = update = _refuse

    def __reduce__(self):
        return (FrozenDict, (dict(self),))

    def __repr__(self) -> str:
        return dict.__repr__(self)


def _frozen(value):
    """A dict as a FrozenDict; a list or tuple with its dicts frozen (the sequence kept)."""
    if isinstance(value, dict) and not isinstance(value, FrozenDict):
        return FrozenDict(value)
    if type(value) in (list, tuple):  # not a namedtuple: its fields stay as they are
        return type(value)(_frozen(v) for v in value)
    return value


def freeze_fields(result, *names: str) -> None:
    """In a frozen dataclass's ``__post_init__``: make the named fields read-only, a dict as a
    :class:`FrozenDict`, an array as a read-only view of itself (None stays None). It guards
    against changing a result by accident, not on purpose: a pickled or deep-copied result
    is a separate copy, writable, and a view's flag can be set back."""
    for name in names:
        value = getattr(result, name)
        if isinstance(value, dict):
            value = FrozenDict(value)
        elif hasattr(value, "flags"):  # a numpy array, without importing numpy here
            value = value.view()
            value.flags.writeable = False
        object.__setattr__(result, name, value)
