"""`python -m regrasp.cli`: the `regrasp` command."""

import sys

from . import main

if __name__ == "__main__":
    sys.exit(main())
