"""``python -m chaoscam.cli``: the ``chaoscam`` command."""

import sys

from chaoscam.cli import main

sys.exit(main())
