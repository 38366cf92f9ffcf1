"""``python -m ladders``: see ``ladders.cli``."""

import sys

from ladders.cli import main

sys.exit(main())
