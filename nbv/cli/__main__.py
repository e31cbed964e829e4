"""`python -m nbv.cli`: the `nbv` command."""

import sys

from nbv.cli import main

sys.exit(main())
