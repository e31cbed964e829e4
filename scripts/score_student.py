"""Can a student that ranks the teacher's candidate steps follow it? (issue 26, round 23; validation only).

The default's students (SAC with an imitation term, `nbv.rl.train`) regress the teacher's one best step
with a Gaussian's mode: where the teacher's best steps either way tie (a building seen from one side looks
like its mirror) the fit is their mean, a short step (round 18), and 90 students of rounds 17 to 22 sit
1.5 to 3 coverage points under their teacher at the same metres. This student keeps the actor's trunk
(`nbv.rl.agent.ActorNet.features`: frames, viewpoints, the Bag of Views vector) and ends it in one value
per candidate step of the teacher (`nbv.rl.expert.CANDIDATES`, 125), fitted by cross-entropy to the
softmax of the teacher's scores over a temperature (`--temperature`, coverage points); it flies the
candidate of highest value. Ties then cost nothing: either mirror is a best step.

States come from the default preset's training env on its training buildings (the view lattice), each
labelled with all 125 of the teacher's scores (`NBVEnv.expert_scores`): `--episodes` flown by the teacher
with a share `--epsilon` of random candidate steps, then `--dagger` rounds of `--episodes` flown by the
student (argmax, the same share of random steps), each followed by a fit on everything pooled. A share
`--held` of the first round's episodes is never fitted: the student's regret there (the teacher's best
score less the score of the student's choice, coverage points) says how well it ranks. With
`--privileged-unseen` the student also reads the unseen map (`nbv.rl.unseen_map`, a diagnostic that
reads the true mesh); without it, what a UAV captures alone. Then it flies the validation buildings
(exact renders, 13 views, `scripts/looks_eval.py`'s scoring and checks), with blank images too.

Writes OUT/results.md, results.json, coverage.png, fit.json (per round: states, held regret, the share of
held states whose choice is within 0.1 point of the best) and student.pt (the network's weights).

    python scripts/score_student.py --out paper_results/selection/round23/score_student --work WORK
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import torch
from tensordict import TensorDict
from torch import nn
from tqdm import tqdm

from common.io import atomic_folder, write_json
from common.provenance import git_commit, portable_record
from common.threads import set_torch_threads
from nbv.planning.config import PlanSettings
from nbv.planning.registry import make_planner
from nbv.rl.agent import ActorNet
from nbv.rl.bov_observation import BOV_KEY, bov_observation_size
from nbv.rl.config import EnvConfig, NetworkConfig
from nbv.rl.env import NBVEnv
from nbv.rl.expert import CANDIDATES
from nbv.rl.presets import default_preset

sys.path.insert(0, str(Path(__file__).parent))
import looks_eval  # noqa: E402
from dagger import minibatch_passes  # noqa: E402

OBSERVATION = ("pixels", "viewpoints", BOV_KEY)
"""The state keys the student reads."""
NEAR_TIE = 0.1
"""Coverage points within which a choice counts as one of the teacher's best (`--teacher-tolerance`'s)."""


class ScoreNet(nn.Module):
    """The actor's trunk (`ActorNet.features`) ending in one value per teacher candidate step (125)."""

    def __init__(self, env: EnvConfig, network: NetworkConfig) -> None:
        super().__init__()
        self.trunk = ActorNet(env.history, env.obs_size, network, bov_observation_size(env))
        h = network.hidden
        self.trunk.head = nn.Sequential(nn.Linear(2 * h, h), nn.ReLU(), nn.Linear(h, len(CANDIDATES)))

    def forward(self, state: TensorDict) -> torch.Tensor:
        """Values (*, 125) of the state(s)' candidate steps."""
        features, batch = self.trunk.features(state["pixels"], state["viewpoints"], state.get(BOV_KEY))
        return self.trunk.head(features).reshape(*batch, len(CANDIDATES))


def choose(net: ScoreNet, state: TensorDict) -> int:
    """The candidate step of highest value in one state."""
    with torch.no_grad():
        return int(net(state.select(*OBSERVATION)).argmax())


def fly(env: NBVEnv, episodes: int, epsilon: float, rng: np.random.Generator, net: ScoreNet | None,
        desc: str) -> list[list[TensorDict]]:
    """`episodes` episodes, each a list of its states labelled with the teacher's scores (key `scores`),
    flown by the teacher's best step (no `net`) or the student's choice, a share `epsilon` of steps random."""
    flown = []
    for _ in tqdm(range(episodes), desc=desc, unit="episode"):
        state, done, states = env.reset(), False, []
        while not done:
            scores = env.expert_scores()
            states.append(state.select(*OBSERVATION).set("scores", torch.from_numpy(scores).float()))
            k = int(rng.integers(len(CANDIDATES))) if rng.random() < epsilon else (
                int(np.argmax(scores)) if net is None else choose(net, state))
            state = env.step(state.set("action", torch.from_numpy(CANDIDATES[k]).float()))
            done, state = bool(state["next", "done"]), state["next"]
        flown.append(states)
    return flown


def cross_entropy(net: ScoreNet, batch: TensorDict, temperature: float) -> torch.Tensor:
    """The cross-entropy of the student's softmax to the teacher's scores' softmax over `temperature`."""
    target = torch.softmax(batch["scores"] / temperature, dim=-1)
    return -(target * torch.log_softmax(net(batch), dim=-1)).sum(-1).mean()


def regret(net: ScoreNet, states: TensorDict) -> tuple[float, float]:
    """The mean regret of the student's choices over `states` (coverage points) and the share of them within
    `NEAR_TIE` of the teacher's best."""
    with torch.no_grad():
        chosen = net(states).argmax(-1)
    scores = states["scores"]
    lost = scores.max(-1).values - scores.gather(-1, chosen[:, None])[:, 0]
    return float(lost.mean()), float((lost <= NEAR_TIE).float().mean())


def fit(net: ScoreNet, data: TensorDict, held: TensorDict, epochs: int, batch: int, lr: float,
        temperature: float, generator: torch.Generator) -> list[dict]:
    """`epochs` passes of minibatch Adam on the cross-entropy; per pass, the training loss and the held
    states' regret."""
    def measured() -> dict:
        held_regret, near = regret(net, held)
        return {"held_regret": held_regret, "held_near_best": near}

    return minibatch_passes(torch.optim.Adam(net.parameters(), lr=lr), data, epochs, batch, generator,
                            lambda part: cross_entropy(net, part, temperature), measured)


class StudentPlanner(looks_eval.EnvPlanner):
    """The student's flight: an env on the plan's settings, stepped by its highest-valued candidate."""

    name = "score-student"

    def __init__(self, net: ScoreNet, blank_images: bool = False) -> None:
        self.net, self.blank_images = net, blank_images

    def env(self, world, views: int) -> NBVEnv:
        """The plan's env (its renders), with blank images if asked."""
        return NBVEnv(replace(world.env, episode_views=views), seed=world.seed, source=world.source,
                      blank_images=self.blank_images)

    def act(self, state: TensorDict) -> torch.Tensor:
        """The candidate step the student values most."""
        return torch.from_numpy(CANDIDATES[choose(self.net, state)]).float()


def merge_blank(results: dict, name: str) -> None:
    """Fold the `NAME-blank` planner's runs into `name`'s as its blank-image coverage (as `evaluate` keeps a
    policy's), so the report and the checks read the blank drop."""
    blind = results.pop(f"{name}-blank")
    results[name]["summary"]["blank"] = blind["summary"]["coverage"]
    for scene, doc in results[name]["runs"].items():
        doc["blank"] = {seed: run["coverage"] for seed, run in blind["runs"][scene]["runs"].items()}


def stack(episodes: list[list[TensorDict]]) -> TensorDict:
    """The episodes' states in one batch."""
    return torch.stack([state for states in episodes for state in states])


def arguments() -> argparse.Namespace:
    """The command line (module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=200, help="episodes flown per round")
    parser.add_argument("--dagger", type=int, default=1, help="rounds flown by the student")
    parser.add_argument("--epsilon", type=float, default=0.3, help="share of random candidate steps")
    parser.add_argument("--held", type=float, default=0.1, help="share of the first round's episodes held")
    parser.add_argument("--epochs", type=int, default=12)
    parser.add_argument("--batch", type=int, default=64)
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--temperature", type=float, default=0.5, help="of the teacher's softmax, points")
    parser.add_argument("--privileged-unseen", action="store_true", help="the student reads the unseen map")
    parser.add_argument("--name", default="score-student", help="the student's name in the tables")
    parser.add_argument("--seed", type=int, default=0)
    looks_eval.study_arguments(parser)
    return parser.parse_args()


def main() -> None:
    args = arguments()
    looks_eval.refuse_held_out(args.scenes)
    config = default_preset()
    set_torch_threads(config.collector.threads)
    torch.manual_seed(args.seed)
    trained = replace(config.env, privileged_unseen=args.privileged_unseen)
    env = NBVEnv(trained, seed=args.seed, reward_terms=replace(config.reward, imitation=0.0))
    net, rng = ScoreNet(trained, config.network), np.random.default_rng(args.seed)
    generator = torch.Generator().manual_seed(args.seed)
    first = fly(env, args.episodes, args.epsilon, rng, None, "teacher flies")
    cut = max(1, int(round(args.held * len(first))))
    held, pooled, log = stack(first[:cut]), first[cut:], []
    for round_ in range(args.dagger + 1):
        if round_:
            pooled += fly(env, args.episodes, args.epsilon, rng, net, f"student flies ({round_})")
        data = stack(pooled)
        log.append({"round": round_, "states": len(data), "held_states": len(held),
                    "passes": fit(net, data, held, args.epochs, args.batch, args.lr, args.temperature,
                                  generator)})
        print({k: v for k, v in log[-1].items() if k != "passes"}, log[-1]["passes"][-1], flush=True)
    net.eval()
    planners = {name: (make_planner(name, PlanSettings()), False) for name in ("orbit", "orbit2", "random")}
    planners[args.name] = (StudentPlanner(net), False)
    planners[f"{args.name}-blank"] = (StudentPlanner(net, blank_images=True), False)
    args.work.mkdir(parents=True, exist_ok=True)
    for stale in (args.work / args.name, args.work / f"{args.name}-blank"):  # a new student each run
        for saved in stale.glob("*.json"):
            saved.unlink()
    results = looks_eval.evaluate(planners, trained, args.scenes, args.seeds, args.views, args.work)
    merge_blank(results, args.name)
    checks = looks_eval.policy_acceptance(results, args.scenes, [args.name])
    table = looks_eval.report(results, args.scenes, args.seeds, args.views, "orbit", checks)
    outputs = (*looks_eval.STUDY_OUTPUTS, "fit.json", "student.pt")
    with atomic_folder(args.out, overwrite=True, outputs=outputs) as out:
        looks_eval.write_study(out, args, results, checks, table,
                               f"{args.views} views: a student ranking the teacher's steps")
        write_json(out / "fit.json", portable_record({"commit": git_commit(), "command": sys.argv,
                                                      "rounds": log}))
        torch.save(net.state_dict(), out / "student.pt")
    print(table)


if __name__ == "__main__":
    main()
