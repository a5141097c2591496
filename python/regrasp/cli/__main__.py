"""`python -m regrasp.cli`: the `regrasp` command."""

import sys

from . import main

sys.exit(main())
