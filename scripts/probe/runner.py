"""Re-run the reliability probe at d439c96 (issue 28) against this checkout: every failing case F1-F39 of
`shared/reviews/reliability-probe-d439c96.md` with its reproduction, and passing cases rebuilt from the
report's method per part (SIGKILL with the output hashed before and after, two writers, a 3 MiB tmpfs,
training killed and resumed, dataset / policy / mesh mutations, bad values).

Each case runs in its own folder under `--scratch`, niced (`nice -n 10`), at most two at a time, with a
timeout and a cap on its process tree's RSS; its outcome is classed as the report's columns: passed,
traceback, vague (an error that does not name what is wrong), silent (invalid data accepted, or a wrong
result), lost-partial, hang-memory. Settings are the report's: 64x48 at 1 spp, DS8 / DS40.

    PYTHONPATH=. python scripts/reliability_probe.py --scratch /tmp/probe --out paper_results/reliability
    PYTHONPATH=. python scripts/reliability_probe.py --only F3,F24   # some cases only
    PYTHONPATH=. python scripts/reliability_probe.py --parts 3 --update   # re-run part 3 into OUT's results

prints the counts per part and writes OUT/probe.json and OUT/probe.md (per case: part, id, command, outcome,
last printed line) with the commit it ran at.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from probe.cli_values import part8
from probe.disk import part3
from probe.harness import ENV, OUTCOMES, PARTS, ROOT, Case, environment, run_case, sh
from probe.kills import part1
from probe.meshes import part7
from probe.policy_files import part6
from probe.readers import part5
from probe.resume import part4
from probe.writers import part2

ALL_PARTS = (part1, part2, part3, None, part5, part6, part7, part8)




def datasets(scratch: Path) -> None:
    """DS8 and DS40 of the report, written once into `scratch`."""
    for views in (8, 40):
        out = scratch / f"DS{views}"
        if not (out / "transforms.json").exists():
            done = sh(
                f"nbv scan test_building circle --views {views} $CAM --out {out} --overwrite", scratch, 600
            )
            if done.rc != 0:
                raise SystemExit(f"DS{views} failed: {done.last}")


def all_cases(scratch: Path) -> list[Case]:
    """Every case, the report's failures (F1-F39) first."""
    cases = [c for part in ALL_PARTS for c in (part() if part else part4(scratch))]
    return sorted(cases, key=lambda c: (not c.id.startswith("F"), c.part))


def counts(records: list[dict]) -> dict[int, dict[str, int]]:
    """Per part: tried and the count of each outcome."""
    table = {}
    for part in PARTS:
        rows = [r for r in records if r["part"] == part]
        table[part] = {
            "tried": len(rows),
            **{o: sum(r["outcome"] == o for r in rows) for o in OUTCOMES},
            "harness-error": sum(r["outcome"] == "harness-error" for r in rows),
        }
    return table


def markdown(table: dict, records: list[dict], commit: str, command: str) -> str:
    """probe.md: the counts per part, then every case."""
    cols = ("tried", *OUTCOMES, "harness-error")
    lines = [
        f"# Reliability probe re-run at {commit}",
        "",
        f"`{command}`",
        "",
        "| part | " + " | ".join(cols) + " |",
        "|---" * (len(cols) + 1) + "|",
    ]
    lines += [f"| {p}. {PARTS[p]} | " + " | ".join(str(table[p][c]) for c in cols) + " |" for p in PARTS]
    total = {c: sum(table[p][c] for p in PARTS) for c in cols}
    lines += [
        "| **total** | " + " | ".join(f"**{total[c]}**" for c in cols) + " |",
        "",
        "| part | case | outcome | command | last line |",
        "|---|---|---|---|---|",
    ]
    esc = lambda s: s.replace("|", "\\|").replace("\n", " ")[:300]  # noqa: E731
    lines += [
        f"| {r['part']} | {r['id']} | {r['outcome']} | `{esc(r['command'])}` | {esc(r['last_line'])} |"
        for r in sorted(records, key=lambda r: (r["part"], r["id"]))
    ]
    return "\n".join(lines) + "\n"


def print_table(table: dict) -> None:
    """The counts per part on stdout."""
    cols = ("tried", *OUTCOMES, "harness-error")
    print(f"{'part':<6}" + "".join(f"{c:>14}" for c in cols))
    for part in PARTS:
        print(f"{part:<6}" + "".join(f"{table[part][c]:>14}" for c in cols))


def options(argv: list[str] | None) -> argparse.Namespace:
    """The command line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scratch", type=Path, default=Path("/tmp/reliability-probe"))
    parser.add_argument("--out", type=Path, default=ROOT / "paper_results/reliability")
    parser.add_argument("--only", default="", help="comma-separated case ids or prefixes (e.g. F3,kill-scan)")
    parser.add_argument("--parts", default="", help="comma-separated part numbers")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--timeout-factor", type=float, default=1.0, help="scale every case's timeout")
    parser.add_argument("--update", action="store_true",
                        help="keep OUT/probe.json's records of the cases not run now (re-running some)")
    return parser.parse_args(argv)


def git_state() -> tuple[str, bool]:
    """The checkout's short commit, and whether its tree is dirty."""
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain"], cwd=ROOT, capture_output=True, text=True)
    return commit, bool(dirty.stdout.strip())


def write_results(out: Path, records: list[dict], commit: str, dirty: bool, command: str,
                  update: bool) -> dict:
    """OUT/probe.json and OUT/probe.md (with `update`, merged into the records already there: each record
    names the commit it ran at); the counts per part."""
    commands = [command]
    for record in records:
        record["commit"] = commit + ("+dirty" if dirty else "")
    if update and (out / "probe.json").is_file():
        old = json.loads((out / "probe.json").read_text())
        fresh = {r["id"] for r in records}
        kept = [{"commit": old["commit"], **r} for r in old["cases"] if r["id"] not in fresh]
        records, commands = kept + records, [*old.get("commands", [old["command"]]), command]
    table = counts(records)
    out.mkdir(parents=True, exist_ok=True)
    doc = {"commit": commit, "dirty_tree": dirty, "command": command, "commands": commands, "counts": table,
           "cases": records}
    (out / "probe.json").write_text(json.dumps(doc, indent=1) + "\n")
    (out / "probe.md").write_text(markdown(table, records, commit + (" (dirty)" if dirty else ""),
                                           "`, then `".join(commands)))
    return table


def main(argv: list[str] | None = None) -> int:
    """Run the selected cases, print the counts per part and write OUT/probe.json and OUT/probe.md."""
    args = options(argv)
    args.scratch = args.scratch.resolve()
    args.scratch.mkdir(parents=True, exist_ok=True)
    ENV.update(environment(args.scratch))
    datasets(args.scratch)
    cases = all_cases(args.scratch)
    if args.only:
        cases = [c for c in cases if any(c.id == o or c.id.startswith(o + "-") for o in args.only.split(","))]
    for case in cases:
        case.timeout = int(case.timeout * args.timeout_factor)
    if args.parts:
        cases = [c for c in cases if str(c.part) in args.parts.split(",")]
    commit, dirty = git_state()
    print(f"{len(cases)} cases at {commit}{' (dirty tree)' if dirty else ''}", flush=True)
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        records = list(pool.map(lambda c: run_case(c, args.scratch), cases))
    command = "PYTHONPATH=. nice -n 10 python scripts/reliability_probe.py " + " ".join(
        "SCRATCH" if Path(a).resolve() == args.scratch else a for a in (argv or sys.argv[1:]))
    print_table(write_results(args.out, records, commit, dirty, command, args.update))
    return 0 if all(r["outcome"] == "passed" for r in records) else 1
