"""`nbv mission PLAN_DIR --lat LAT --lon LON --target-size-m S --out FILE.plan|FILE.kml`: a plan's views as a
UAV mission (`nbv.mission`)."""

from __future__ import annotations

from collections.abc import Sequence

from nbv.cli.parse import parse
from nbv.mission.config import MissionConfig
from nbv.mission.write import describe, write_mission


def main(args: Sequence[str], prog: str) -> int:
    """Parse `MissionConfig`, write the mission file, say what it holds."""
    config = parse(MissionConfig, args, prog)
    print(describe(write_mission(config), config))
    return 0
