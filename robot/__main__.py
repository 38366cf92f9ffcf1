"""``python -m robot``: see ``robot.cli``."""

import sys

from robot.cli import main

sys.exit(main())
