"""How good is the privileged teacher of `--imitation` (nbv.rl.expert)? Its views against the tuned orbit's.

On each validation building and start view (seed), the teacher flies 13 views in a training env (the
view lattice, its seen samples at the nodes, the flight-cost weight `--flight-reward`), and its exact
viewpoints are scored as `scripts/looks_eval.py` scores every planner: the share of the true surface the
views see, and the metres along the viewing shell. A student can at best follow its teacher, so a
teacher below the orbit is not worth imitating. Validation buildings only.

    python scripts/teacher_eval.py --flight-reward 0.5 --teacher-horizon 0 --teacher-discount 1 \
        --out paper_results/selection/round7/teacher --work WORK

`--action-mode` and `--relative-step` give the teacher another action space than the `looks` preset's
(relative steps of 1/8 of each range): `orbit` with a step of 1/6 holds the two tuned rings' path.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

from nbv.experiments.online_acceptance import building_mean
from nbv.planning.config import PlanSettings
from nbv.planning.registry import make_planner
from nbv.rl.config import EnvConfig, RewardConfig
from nbv.rl.env import NBVEnv
from nbv.rl.expert import EXPERT_KEY
from nbv.rl.presets import looks_preset

sys.path.insert(0, str(Path(__file__).parent))
from looks_eval import EnvPlanner, conclude, evaluate, refuse_held_out, study_arguments  # noqa: E402


class TeacherPlanner(EnvPlanner):
    """The teacher's own flight: a training env on the lattice, stepped by its expert action."""

    name = "teacher"

    def __init__(self, trained: EnvConfig, terms: RewardConfig) -> None:
        self.trained, self.terms = trained, terms

    def env(self, world, views: int) -> NBVEnv:
        """A training env on the building, with the teacher's reward terms."""
        config = replace(self.trained, scenes=world.env.scenes, episode_views=views)
        return NBVEnv(config, seed=world.seed, reward_terms=self.terms)

    def act(self, state):
        """The teacher's label of the state."""
        return state[EXPERT_KEY]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flight-reward", type=float, nargs="+", default=[0.5])
    parser.add_argument("--flight-allowance", type=float, default=0.0,
                        help="metres of an episode free of --flight-excess-reward (nbv.rl.flight_cost)")
    parser.add_argument("--flight-excess-reward", type=float, default=0.0,
                        help="the hinge's weight per metre past the allowance; 0: the linear term alone")
    parser.add_argument("--teacher-horizon", type=int, default=3, help="0: to the end of the budget")
    parser.add_argument("--teacher-discount", type=float, default=0.9)
    parser.add_argument("--action-mode", choices=("relative", "orbit", "forward"), default=None,
                        help="the teacher's action space (default: the looks preset's)")
    parser.add_argument("--relative-step", type=float, default=None,
                        help="its largest step per view, a fraction of each range (default: the preset's)")
    study_arguments(parser)
    args = parser.parse_args()
    refuse_held_out(args.scenes)
    preset = looks_preset().env
    trained = replace(preset, action_mode=args.action_mode or preset.action_mode,
                      relative_step=args.relative_step or preset.relative_step)
    planners = {name: (make_planner(name, PlanSettings()), False) for name in ("orbit", "orbit2", "random")}
    teacher = f"teacher_h{args.teacher_horizon}_d{args.teacher_discount:g}"
    if trained != preset:
        teacher += f"_{trained.action_mode}{trained.relative_step:.3g}"
    hinge = f"_a{args.flight_allowance:g}x{args.flight_excess_reward:g}" if args.flight_excess_reward else ""
    for w in args.flight_reward:
        terms = RewardConfig(imitation=1.0, flight=w, flight_allowance=args.flight_allowance,
                             flight_excess=args.flight_excess_reward, teacher_horizon=args.teacher_horizon,
                             teacher_discount=args.teacher_discount)
        planners[f"{teacher}_w{w:g}{hinge}"] = (TeacherPlanner(trained, terms), False)
    results = evaluate(planners, trained, args.scenes, args.seeds, args.views, args.work)
    conclude(args, results, [name for name in planners if name.startswith(teacher)],
             f"{args.views} views: the teacher vs the tuned orbit")
    print("mean coverage:", {n: round(building_mean(d["summary"]["coverage"]), 1)
                             for n, d in results.items()})


if __name__ == "__main__":
    sys.exit(main())
