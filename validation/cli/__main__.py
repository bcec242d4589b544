"""``python -m validation.cli``: the ``specref`` command."""

import sys

from validation.cli import run

sys.exit(run())
