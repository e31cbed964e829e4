"""Re-run the reliability probe at d439c96 (issue 28) against this checkout: the entry point of the
`scripts/probe/` package (its runner's docstring tells the cases, the outcomes and the options).

    PYTHONPATH=. python scripts/reliability_probe.py --scratch /tmp/probe --out paper_results/reliability
    PYTHONPATH=. python scripts/reliability_probe.py --only F3,F24   # some cases only
"""

from __future__ import annotations

import sys

from probe.harness import ROOT
from probe.runner import main

if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main())
