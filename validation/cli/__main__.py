"""``python -m validation.cli``: the ``specref`` command."""

import sys

from validation.cli import main

sys.exit(main())
