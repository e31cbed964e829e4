"""Does a policy look? Trained candidates against the tuned orbit on validation buildings (issue 26, round 5).

For each policy (`--policy NAME=PATH`, a `policy.pt`) and baseline planner (`--baselines`, default the tuned
`orbit` and `random`), on each validation building and start view (seed), 13 views by default:

- coverage: the share of the true surface the views see (`nbv.recon.visibility`, samples seeded by the
  seed; the model-selection score of `nbv.planning.selection`), exact renders at the policy's settings;
- metres: the flight from the start view through the views along the viewing shell (`flight_record`);
- blank: a policy's coverage with every captured image replaced by a blank one (`blank_images`): a
  policy that looks loses coverage;
- spread: from the same start view, the mean distance (metres, positions relative to each building's
  centre) between the i-th camera positions on two different buildings, over every pair and seed: an
  open-loop policy flies the same path everywhere (0 m);
- checks (with `orbit` among the baselines): each policy's issue-26 acceptance checks against the tuned
  orbit, by the rule `nbv online` applies to held-out buildings (`nbv.experiments.online_acceptance`),
  counted in the table's `checks` column and listed below it.

Validation buildings only: the script refuses held-out ones (`scenes.family_splits.held_out`).

    python scripts/looks_eval.py --policy default=RUNS/default/policy.pt --policy looks=RUNS/looks/policy.pt \
        --out paper_results/selection/round5 --work RUNS/looks_eval
"""

from __future__ import annotations

import argparse
import json
import sys
from abc import abstractmethod
from pathlib import Path

import numpy as np
from tqdm import tqdm

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import git_commit, portable_record
from nbv.experiments.online_acceptance import (
    Runs,
    acceptance_checks,
    acceptance_section,
    building_mean,
    tally,
)
from nbv.features.source import ViewSource
from nbv.flight.record import flight_record
from nbv.flight.spread import pair_spreads_m
from nbv.planning.base import Planner
from nbv.planning.config import PlanSettings
from nbv.planning.policy import PolicyPlanner
from nbv.planning.registry import make_planner
from nbv.planning.world import PlanningWorld
from nbv.recon.visibility import SurfaceVisibility, scene_visibility
from nbv.rl.config import EnvConfig
from nbv.rl.presets import FAMILY_VALIDATION_SCENES, VALIDATION_SCENES
from nbv.rl.validate import evaluation_env_config
from nbv.viz.figures import plot_seed_scores
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.family_splits import held_out
from scenes.spec import SceneSet

SCENES = (*VALIDATION_SCENES, *FAMILY_VALIDATION_SCENES, "family:9", "family:14", "family:29")
"""The validation buildings scored: the default's three, and four validation-split family buildings (a
tower, a courtyard, a U plan, a hall)."""


class Scorer:
    """Flies planners on one settings' validation buildings, one view source and visibility per building."""

    def __init__(self, env: EnvConfig, views: int) -> None:
        self.env, self.views = env, views
        self._sources: dict[str, ViewSource] = {}
        self._visibility: dict[tuple[str, int], SurfaceVisibility] = {}

    def fly(self, planner: Planner, trained: EnvConfig, scene: str, seed: int) -> dict:
        """The planner's views on `scene` from seed `seed`'s start: coverage (%), metres, positions."""
        config = evaluation_env_config(trained, SceneSet(scene=(scene,)))
        if scene not in self._sources:
            self._sources[scene] = ViewSource(config.camera, config.render, config.bov.feature_config(),
                                              config.obs_size, seed)
        world = PlanningWorld(config, seed=seed, source=self._sources[scene])
        chosen = planner.plan(world, self.views)
        loaded = world.target
        if (scene, seed) not in self._visibility:
            self._visibility[scene, seed] = scene_visibility(loaded, config.camera, seed=seed)
        poses = [viewpoint_to_c2w(v, loaded.center()) for v in chosen]
        coverage = self._visibility[scene, seed].coverage(poses)
        return {"coverage": 100.0 * coverage, "flight_m": flight_record(world.start, chosen)["flight_m"],
                "viewpoints": [v.as_array().tolist() for v in chosen],
                "start": world.start.as_array().tolist()}


class EnvPlanner(Planner):
    """A flight stepped through an env from the plan's start view: a subclass makes the env (`env`) and picks
    each action from the state (`act`)."""

    @abstractmethod
    def env(self, world: PlanningWorld, views: int):
        """The env to fly `views` views in, seeded as the plan (so it starts at the plan's start view)."""

    @abstractmethod
    def act(self, state):
        """The action to take in `state` (a TensorDict of the env's)."""

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """The start view, then the view of each action (13 in all without a count)."""
        env = self.env(world, views or 13)
        state = env.reset()
        if env.viewpoint != world.start:
            raise RuntimeError(f"{self.name} starts at {env.viewpoint}, the plan at {world.start}")
        chosen = [env.viewpoint]
        for _ in range((views or 13) - 1):
            state = env.step(state.set("action", self.act(state)))["next"]
            chosen.append(env.viewpoint)
        return chosen


def spread_m(runs: dict[tuple[str, int], dict], scenes: list[str], seeds: list[int]) -> float:
    """Mean distance between the i-th camera positions on two buildings from the same start, metres."""
    paths = {s: {seed: [Viewpoint(*v) for v in runs[s, seed]["viewpoints"]] for seed in seeds}
             for s in scenes}
    return float(np.mean(list(pair_spreads_m(paths).values())))


def score_scene(scorer: Scorer, planner: Planner, env: EnvConfig, scene: str, seeds: list[int],
                blank: Planner | None) -> dict:
    """One planner's runs on one building (and with `blank`, its blank-image coverage), by seed."""
    runs = {str(seed): scorer.fly(planner, env, scene, seed) for seed in tqdm(seeds, desc=scene, unit="run")}
    blanks = {str(seed): scorer.fly(blank, env, scene, seed)["coverage"] for seed in seeds} if blank else {}
    return {"runs": runs, "blank": blanks}


def summarise(by_scene: dict[str, dict], scenes: list[str], seeds: list[int]) -> dict:
    """A planner's summary: per building, mean coverage, metres (and blank coverage); the spread."""
    def mean(value) -> dict[str, float]:
        return {s: float(np.mean([value(by_scene[s], str(seed)) for seed in seeds])) for s in scenes}

    runs = {(s, seed): by_scene[s]["runs"][str(seed)] for s in scenes for seed in seeds}
    summary = {"coverage": mean(lambda doc, seed: doc["runs"][seed]["coverage"]),
               "flight_m": mean(lambda doc, seed: doc["runs"][seed]["flight_m"]),
               "spread_m": spread_m(runs, scenes, seeds)}
    if by_scene[scenes[0]]["blank"]:
        summary["blank"] = mean(lambda doc, seed: doc["blank"][seed])
    return summary


def work_file(work: Path, name: str, scene: str) -> Path:
    """Where a study keeps one planner's runs on one building in its work folder."""
    return work / name / f"{scene.replace(':', '_')}.json"


def evaluate(planners: dict[str, tuple[Planner, bool]], trained: EnvConfig, scenes: list[str],
             seeds: list[int], views: int, work: Path, blank_images: bool = True,
             blanks: dict[str, Planner] | None = None) -> dict:
    """Every planner's runs and summary (policies also with blank images, unless `blank_images` is off, and
    a planner named in `blanks` with its twin there that is given blank images); each (planner, building)
    kept in `work/NAME/SCENE.json` and reused while its key holds and it has what is asked (so buildings
    can be scored by processes side by side, then gathered)."""
    scorer, results = Scorer(trained, views), {}
    for name, (planner, is_policy) in planners.items():
        checkpoint = Path(planner.checkpoint) if is_policy else None
        key = {"seeds": seeds, "views": views, "checkpoint": str(checkpoint),
               "mtime": checkpoint.stat().st_mtime if checkpoint else None}
        env = planner.env_config if is_policy else trained
        blank = PolicyPlanner(checkpoint, blank_images=True) if is_policy else (blanks or {}).get(name)
        blank = blank if blank_images else None
        by_scene = {}
        for scene in scenes:
            saved = work_file(work, name, scene)
            doc = json.loads(saved.read_text()) if saved.is_file() else None
            if doc is not None and doc["key"] == key and (blank is None or doc["result"]["blank"]):
                by_scene[scene] = doc["result"]
                continue
            by_scene[scene] = score_scene(scorer, planner, env, scene, seeds, blank)
            saved.parent.mkdir(parents=True, exist_ok=True)
            write_json(saved, {"key": key, "result": by_scene[scene]})
        results[name] = {"summary": summarise(by_scene, scenes, seeds), "runs": by_scene}
    return results


def acceptance_runs(results: dict, scenes: list[str], blank: bool = False) -> Runs:
    """The runs in `nbv online`'s form (per building, per planner, records with gt coverage, metres,
    viewpoints and seed), for the acceptance rule; with `blank`, the policies' blank-image coverages."""
    def records(doc: dict) -> list[dict]:
        if blank:
            return [{"gt": {"coverage": c / 100.0}, "seed": int(seed)} for seed, c in doc["blank"].items()]
        return [{"gt": {"coverage": r["coverage"] / 100.0}, "flight_m": r["flight_m"],
                 "viewpoints": r["viewpoints"], "seed": int(seed)} for seed, r in doc["runs"].items()]

    return {s: {name: records(d["runs"][s]) for name, d in results.items()
                if not blank or d["runs"][s]["blank"]} for s in scenes}


def policy_acceptance(results: dict, scenes: list[str], policies: list[str]) -> dict[str, list[dict]]:
    """Each policy's acceptance checks (`nbv.experiments.online_acceptance`) on these runs."""
    blank = acceptance_runs(results, scenes, blank=True)
    return acceptance_checks(acceptance_runs(results, scenes), blank if any(blank.values()) else None,
                             policies)


def report(results: dict, scenes: list[str], seeds: list[int], views: int, reference: str,
           checks: dict[str, list[dict]]) -> str:
    """The results table (markdown): per planner, mean coverage, its gap to `reference`, metres, the looks
    figures, the acceptance checks passed (`checks`, by policy) and each building's coverage; then the
    checks one by one."""
    ref = results[reference]["summary"]["coverage"]
    rows = []
    for name, doc in results.items():
        summary = doc["summary"]
        cov = summary["coverage"]
        mean = building_mean(cov)
        blank = summary.get("blank")
        drop = f"{mean - building_mean(blank):.1f}" if blank else "-"
        rows.append([name, f"{mean:.1f}", f"{mean - building_mean(ref):+.1f}",
                     f"{min(cov[s] - ref[s] for s in scenes):+.1f}",
                     f"{building_mean(summary['flight_m']):.1f}", f"{summary['spread_m']:.2f}", drop,
                     passed(checks[name]) if name in checks else "-", *(f"{cov[s]:.1f}" for s in scenes)])
    head = ["planner", "coverage %", f"vs {reference}", f"worst vs {reference}", "metres", "spread m",
            "blank drop", "checks", *scenes]
    section = "\n".join(acceptance_section(checks, len(scenes))) + "\n" if checks else ""
    return (f"Visible-surface coverage (%) of the true mesh at {views} views, mean over start views "
            f"{', '.join(map(str, seeds))}, on validation buildings; metres along the viewing shell; spread: "
            "mean distance between camera positions on two buildings from the same start; blank drop: "
            "coverage lost with blank images; checks: issue 26's acceptance checks passed (below).\n\n"
            + markdown_table(head, rows) + section)


def passed(checks: list[dict]) -> str:
    """How many of a policy's acceptance checks pass, of those with a bar (`tally`): "4/6"."""
    return "{}/{}".format(*tally(checks))


STUDY_OUTPUTS = ("results.json", "results.md", "coverage.png")
"""The files `write_study` writes."""


def write_study(out: Path, args: argparse.Namespace, results: dict, checks: dict[str, list[dict]], table: str,
                title: str, **record) -> None:
    """Into a study's open output folder `out`: its table (results.md), chart (coverage.png, titled `title`)
    and record (results.json: the commit, the buildings, start views and views of `args`, `record`'s
    entries, the results, the checks and the command line)."""
    write_text(out / "results.md", table)
    plot_seed_scores({n: list(d["summary"]["coverage"].values()) for n, d in results.items()},
                     out / "coverage.png", "visible coverage % (validation buildings)", title)
    write_json(out / "results.json", portable_record({
        "commit": git_commit(), "scenes": args.scenes, "seeds": args.seeds, "views": args.views, **record,
        "results": results, "checks": checks, "command": sys.argv}))


def conclude(args: argparse.Namespace, results: dict, names: list[str], title: str) -> None:
    """A study's end: the checks of the planners `names`, the table against the tuned orbit, the output
    folder (`write_study`, its chart titled `title`); the table printed."""
    checks = policy_acceptance(results, args.scenes, names)
    table = report(results, args.scenes, args.seeds, args.views, "orbit", checks)
    with atomic_folder(args.out, overwrite=True, outputs=STUDY_OUTPUTS) as out:
        write_study(out, args, results, checks, table, title)
    print(table)


def study_arguments(parser: argparse.ArgumentParser) -> None:
    """The options every validation study of this kind takes: buildings, start views, views, out, work."""
    parser.add_argument("--scenes", nargs="+", default=list(SCENES))
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--views", type=int, default=13)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--work", type=Path, required=True, help="per-planner results, reused when re-run")


def refuse_held_out(scenes: list[str]) -> None:
    """Exit with a message if any of `scenes` is held out: these studies choose, so validation only."""
    refused = [s for s in scenes if held_out(s)]
    if refused:
        raise SystemExit(f"held-out buildings are not for choosing: {', '.join(refused)}; give validation "
                         "ones")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", action="append", default=[], metavar="NAME=PATH", required=True)
    parser.add_argument("--baselines", nargs="*", default=["orbit", "random"])
    parser.add_argument("--no-blank", action="store_true",
                        help="skip the blank-image flights (a quicker screen of many policies)")
    study_arguments(parser)
    args = parser.parse_args()
    refuse_held_out(args.scenes)
    policies = {name: PolicyPlanner(path) for name, path in (p.split("=", 1) for p in args.policy)}
    trained = next(iter(policies.values())).env_config
    planners = {name: (p, True) for name, p in policies.items()}
    planners |= {name: (make_planner(name, PlanSettings(), seed=0), False) for name in args.baselines}
    args.work.mkdir(parents=True, exist_ok=True)
    results = evaluate(planners, trained, args.scenes, args.seeds, args.views, args.work, not args.no_blank)
    checks = policy_acceptance(results, args.scenes, list(policies)) if "orbit" in args.baselines else {}
    table = report(results, args.scenes, args.seeds, args.views, args.baselines[0] if args.baselines else
                   next(iter(policies)), checks)
    with atomic_folder(args.out, overwrite=True, outputs=STUDY_OUTPUTS) as out:
        write_study(out, args, results, checks, table, "13 views: policies vs the tuned orbit",
                    policies=dict(p.split("=", 1) for p in args.policy))
    print(table)


if __name__ == "__main__":
    sys.exit(main())
