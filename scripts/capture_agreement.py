"""Measure how a scan re-expressed as other tools' captures refines against the scan itself (issue 27).

Renders (or reuses from the scan cache) the full hemisphere scan of SCENE, writes it as COLMAP text,
COLMAP binary, nerfstudio PNG with an off-centre principal point (a 4 x 2 px crop), nerfstudio JPEG
(quality 95) centred, the same off-centre, and off-centre with small OPENCV distortion, each in a
random similarity frame (the builders of tests/foreign_captures.py), runs
Alg. 1 on each for every (N, W) of the grid, and writes the Jaccard index of each capture's kept frames
against the native scan's, per cell, as JSON and a markdown table; the native scan refined with
another seed (of the reservoir and k-means++ draws) is the control: how far Alg. 1 moves by itself.

    python scripts/capture_agreement.py --scene test_building --out paper_results/captures
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from common.io import markdown_table, write_json, write_text
from common.provenance import git_commit
from nbv.bov.config import BoVRule
from nbv.bov.refine import DatasetRun, kept_view_grid, load_views
from nbv.bov.sweep import PAPER_RANGES, PAPER_WORDS
from render.camera import UAVCamera
from render.scan_cache import full_scan
from render.settings import RenderSettings
from scenes import load_scene

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from foreign_captures import similarity, write_colmap, write_nerfstudio  # noqa: E402

DISTORTION = (0.03, -0.01, 0.0005, 0.0)
"""The small OPENCV k1, k2, p1, p2 of the distorted capture (as in the tests)."""


def kept_grid(path: Path, rule: BoVRule, seed: int = 0) -> dict[tuple[int, int], list[int]]:
    """Kept frames of the dataset or capture at `path` for every (N, W) of the paper's grid."""
    _, feats, azimuths = load_views(DatasetRun(dataset=path, threads=1), rule)
    grid = kept_view_grid([f.descriptors for f in feats], azimuths, PAPER_RANGES, PAPER_WORDS, rule, seed)
    return {cell: result.kept for cell, result in grid.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="test_building")
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    native = full_scan(load_scene(args.scene), UAVCamera(args.width, args.height), settings=RenderSettings())
    rule, sim = BoVRule(), similarity(27)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        captures = {"colmap-text": write_colmap(native, root / "text", "text", sim),
                    "colmap-binary": write_colmap(native, root / "binary", "binary", sim),
                    "nerfstudio-png-offcentre": write_nerfstudio(native, root / "nsp", sim, crop=(4, 2, 0, 0),
                                                                 suffix="png"),
                    "nerfstudio-jpeg-centred": write_nerfstudio(native, root / "nsc", sim),
                    "nerfstudio-jpeg": write_nerfstudio(native, root / "ns", sim, crop=(4, 2, 0, 0)),
                    "nerfstudio-jpeg-distorted": write_nerfstudio(native, root / "nsd", sim, DISTORTION,
                                                                  (4, 2, 0, 0))}
        reference = kept_grid(native.root, rule)
        rows = {"native, seed 1 (control)": kept_grid(native.root, rule, seed=1),
                **{name: kept_grid(path, rule) for name, path in captures.items()}}
    jaccard = {name: {f"{n},{w}": len(set(k) & set(reference[(n, w)])) / len(set(k) | set(reference[(n, w)]))
                      for (n, w), k in grid.items()} for name, grid in rows.items()}
    cells = [f"{n},{w}" for n in PAPER_RANGES for w in PAPER_WORDS]
    table = markdown_table(["capture", *(f"N={c.replace(',', ' W=')}" for c in cells), "min"],
                           [[name, *(f"{j[c]:.2f}" for c in cells), f"{min(j.values()):.2f}"]
                            for name, j in jaccard.items()])
    args.out.mkdir(parents=True, exist_ok=True)
    write_json(args.out / "captures.json", {
        "scene": args.scene, "views": len(native), "size": [args.width, args.height], "jaccard": jaccard,
        "native_kept": {f"{n},{w}": len(k) for (n, w), k in reference.items()}, "commit": git_commit()})
    command = " ".join(["python", *sys.argv])
    write_text(args.out / "captures.md", f"# Kept-frame Jaccard of captures against the native scan "
               f"({args.scene}, {len(native)} views, {args.width}x{args.height})\n\n`{command}`; Alg. 1 with "
               f"the default rule, seed 0; each capture in a random similarity frame; native kept views per "
               f"cell in captures.json.\n\n{table}")
    print(table)


if __name__ == "__main__":
    main()
