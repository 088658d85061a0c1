"""Run the command line with ``python -m cyclecoord``."""

import sys

from .cli import main

sys.exit(main())
