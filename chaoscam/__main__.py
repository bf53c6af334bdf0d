"""``python -m chaoscam``: the same as the ``chaoscam`` command."""

import sys

from chaoscam.cli import main

sys.exit(main())
