"""`nbv refine DATASET --ranges N --words W --out DIR`: Bag-of-Views refinement of a view dataset (Alg. 1)."""

from __future__ import annotations

from collections.abc import Sequence

from tqdm import tqdm

from nbv.bov.refine import RefineConfig, refine_dataset
from nbv.cli.parse import parse
from render.captures.frame import describe_frame


def main(args: Sequence[str], prog: str) -> int:
    """Parse `RefineConfig`, refine the dataset, print what was kept."""
    config = parse(RefineConfig, args, prog)
    with tqdm(desc="features", unit="view", leave=False) as bar:
        summary = refine_dataset(config, bar.update)
    if "capture" in summary:
        print(describe_frame(summary["capture"]))
    print(f"kept {summary['kept_views']} of {summary['source_views']} views "
          f"(N={config.bov.ranges}, W={config.bov.words}) in {summary['seconds']:.1f} s: {config.out}")
    if "links" in summary:
        links = summary["links"]
        print(f"registrable (--min-matches {links['min_matches']}): the paper's rule kept "
              f"{len(links['paper_kept'])}, {len(links['added'])} added to link them, "
              f"{len(links['unlinked'])} kept view(s) unlinked")
    return 0
