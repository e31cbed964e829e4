"""`nbv plan SCENE --planner PLANNER [--views N] --out DIR`: the planners are listed by `--help`, from
`nbv.planning.registry`."""

from __future__ import annotations

import json
from collections.abc import Sequence

from nbv.cli.parse import parse
from nbv.planning.config import PlanConfig
from nbv.planning.plan import plan_scan


def main(args: Sequence[str], prog: str) -> int:
    """Parse `PlanConfig`; plan, capture, reconstruct and score; print the metrics (no `reference` with
    --no-full-scan)."""
    doc = plan_scan(parse(PlanConfig, args, prog))
    keys = ("planner", "views", "gt", "reference", "sfm")
    print(json.dumps({k: doc[k] for k in keys if k in doc}, indent=2))
    return 0
