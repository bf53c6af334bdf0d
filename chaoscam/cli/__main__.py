"""``python -m chaoscam.cli``: the ``chaoscam`` command."""

from chaoscam.cli import entry

entry()
