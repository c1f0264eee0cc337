"""``python -m dial.cli``: the same as the ``dial`` command."""

import sys

from dial.cli import main

sys.exit(main())
