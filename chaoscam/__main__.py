"""``python -m chaoscam``: the same as the ``chaoscam`` command."""

from chaoscam.cli import entry

entry()
