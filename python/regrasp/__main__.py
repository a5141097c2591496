"""`python -m regrasp`: the same as the `regrasp` command."""

import sys

from .cli import main

sys.exit(main())
