"""The `nbv` command: one entry point, one thin module per sub-command.

`nbv --help` lists the commands without importing any of them, so it starts at
once; `nbv COMMAND ...` imports only that command's module, whose `main`
parses its config with tyro (`nbv.cli.parse`) and calls the library.
"""

from __future__ import annotations

import importlib
import os
import sys
import warnings
from collections.abc import Sequence
from typing import NamedTuple

from common.errors import describe
from common.io import output_target
from common.locks import WAIT, OutputBusy, claim, lock_scope
from common.outpath import check_out_path
from nbv.fanout.task import WorkerDied


class Command(NamedTuple):
    """A sub-command: the module under `nbv.cli` that runs it and its one-line help."""

    module: str
    help: str


COMMANDS = {
    "scene": Command("scene", "list built-in scenes, export a target mesh, render a gallery"),
    "scan": Command("scan", "render a hemisphere or circle scan into a view dataset"),
    "refine": Command("refine", "keep the views a Bag of Views finds new (paper Alg. 1)"),
    "refine-sweep": Command("refine_sweep", "kept-view counts over a grid of N and W (paper Table 2)"),
    "export": Command("export", "export a view dataset as a COLMAP model (cameras, images, points3D)"),
    "sfm": Command("sfm", "COLMAP structure from motion on a view dataset, scored against its poses"),
    "reconstruct": Command("reconstruct", "TSDF-fuse a view dataset into a mesh and a point cloud"),
    "evaluate": Command("evaluate", "Chamfer, Hausdorff, coverage and F-score, with a heat map"),
    "train": Command("train", "train the SAC next-best-view policy (resumes a run folder)"),
    "plan": Command("plan", "plan a scan with a planner, reconstruct it and score it"),
    "mission": Command("mission", "write a plan's views as a UAV mission: QGroundControl .plan or KML"),
    "compare": Command("compare", "compare planners over seeds on one scene (table and bar chart)"),
    "online": Command("online", "the shipped policies and the depth option vs baselines, held-out buildings"),
    "plot-training": Command("plot_training", "overlay the learning curves of training runs"),
    "demo": Command("demo", "scan, refine, reconstruct and evaluate a built-in scene"),
    "ablate": Command("ablate", "rendering-quality ablations, one axis at a time (make ablations)"),
    "tables": Command("tables", "the paper's results with seeds: Table 2, Fig. 1, 6, 7, Sec. VII, budgets"),
    "bench": Command("bench", "measure throughput figures (make bench)"),
}
"""Sub-command name -> where it lives, in `--help` order."""

ERRORS = (ValueError, FileExistsError, FileNotFoundError, PermissionError, WorkerDied)
"""Exceptions reported in one line, exit status 2: the user's input at fault, or a unit of work whose
worker died twice (it is named)."""

WAIT_FLAG = "--wait-for-lock"
"""Any command: wait for an output another run is writing instead of failing at once (`common.locks`)."""


def flag_values(args: Sequence[str], flag: str) -> list[str]:
    """The values given to `flag` in `args` (`--out DIR` or `--out=DIR`)."""
    values = [arg.partition("=")[2] for arg in args if arg.startswith(f"{flag}=")]
    return values + [args[i + 1] for i, arg in enumerate(args[:-1]) if arg == flag]


def check_early(args: Sequence[str]) -> None:
    """Before the command is even imported: every `--out` is checked and locked (`hold_output`), every
    `--ray HOST:PORT` must answer."""
    for out in flag_values(args, "--out"):
        check_out_path(out)
        hold_output(out)
    for address in flag_values(args, "--ray"):
        if address.strip() != "auto":
            from nbv.fanout.ray_pool import check_reachable

            check_reachable(address)


def hold_output(out: str) -> None:
    """Hold the lock of `--out` for the whole command (`common.locks`): a second run on it fails at once,
    naming this one. Where no lock can be made, the command's own checks name the fault."""
    target = output_target(out)
    if not os.path.isdir(os.path.dirname(os.path.abspath(target))):
        return  # made (and locked) by the command, once its checks passed
    try:
        claim(target)
    except OutputBusy:
        raise
    except OSError:
        pass


def usage() -> str:
    """The top-level help: every command with its one-line description."""
    width = max(map(len, COMMANDS))
    lines = ["usage: nbv COMMAND [OPTIONS]", "",
             "Appearance-based next-best-view planning toolkit (Bag of Views).", "", "commands:"]
    lines += [f"  {name:<{width}}  {command.help}" for name, command in COMMANDS.items()]
    lines += ["", "`nbv COMMAND --help` lists a command's options.",
              f"{WAIT_FLAG} (any command): wait for an output another run is writing, instead of failing."]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Run the `nbv` command line; bad input exits with status 2 and a one-line message."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv or argv[0] in ("-h", "--help"):
        print(usage(), file=sys.stdout if argv else sys.stderr)
        return 0 if argv else 2
    name, rest = argv[0], argv[1:]
    if name not in COMMANDS:
        print(f"nbv: error: unknown command {name!r} (choose from {', '.join(COMMANDS)})", file=sys.stderr)
        return 2
    shown, warnings.formatwarning = warnings.formatwarning, lambda message, *_, **__: (
        f"nbv {name}: warning: {message}\n")  # one line, without the source line Python adds
    WAIT[0] = WAIT_FLAG in rest
    rest = [arg for arg in rest if arg != WAIT_FLAG]
    try:
        with lock_scope():
            check_early(rest)
            module = importlib.import_module(f"nbv.cli.{COMMANDS[name].module}")
            return int(module.main(rest, prog=f"nbv {name}") or 0)
    except ERRORS as err:
        print(f"nbv {name}: error: {describe(err) if isinstance(err, OSError) else err}", file=sys.stderr)
        return 2
    except OSError as err:  # a full disk, an I/O error: what failed and where, in one line
        print(f"nbv {name}: error: {describe(err)}", file=sys.stderr)
        return 1
    except SystemExit as done:  # tyro's --help (0) and its messages about bad options (2)
        return 0 if done.code is None else done.code if isinstance(done.code, int) else 2
    finally:
        warnings.formatwarning = shown


if __name__ == "__main__":
    sys.exit(main())
