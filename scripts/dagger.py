"""Can the student follow its teacher at all? DAgger on the training buildings (issue 26, round 18).

The default's students are trained by SAC with an imitation term (docs/rl.md §4) on batches of 8, one
gradient step per frame: 6000 steps in all, and the squared distance between the actor's mode and the
teacher's action stays near 0.5 to 1.0 (per state, summed over the three action values in [-1, 1]).
This trains the same actor by supervision alone (Ross et al. 2011, DAgger). The pool of labelled
states starts from `--buffers`: training checkpoints' replay buffers, whose every state carries the
teacher's label (states SAC's actors and exploration visited; a share `--held` is kept aside and never
fitted). Then each iteration flies `--episodes` episodes (the teacher's own actions in iteration 0 when
the pool starts empty, else the student's mode), labels every state visited with the teacher's action
(`nbv.rl.expert`, read by the training env) and adds them to the pool; after the seed states and after
every iteration the actor's mode is fitted to the whole pool (mean squared error, Adam, `--epochs`
passes). The loss on newly flown states before fitting them is the student's error on its own states;
the loss on the held states is its error on states it never fitted. No reward, no critic: the question
is whether the images and poses carry what the teacher knows, given enough updates.

With `--privileged-unseen` the actor also reads the true surface's unseen map (`nbv.rl.unseen_map`, a
diagnostic), as the buffers of runs trained with it hold; `--strip-unseen` fits the actor without it to
such buffers' states, the map cut from each: the same states and labels, with and without the teacher's
knowledge (round 23).

Writes OUT/policy.pt (a policy file `nbv plan --planner policy:OUT/policy.pt` and `scripts/looks_eval.py`
read), OUT/dagger.json (per iteration: states, on-policy loss, fitted loss) and OUT/config.json. The
training env is `nbv train --preset PRESET --scene ...`'s (default: the default preset's buildings):

    python scripts/dagger.py --out RUN18 --iterations 0 --epochs 8 \
        --buffers RUNS/default/member0/checkpoint.pt
    python scripts/dagger.py --out RUN18B --iterations 4 --episodes 60 --scene medieval_tavern \
        --scene random:1
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import torch
from tensordict import TensorDict
from torchrl.envs.utils import ExplorationType, set_exploration_type
from tqdm import tqdm

from common.io import write_json
from common.provenance import config_record, git_commit, portable_record
from common.threads import set_torch_threads
from nbv.rl.bov_observation import BOV_KEY
from nbv.rl.builders import make_environment, make_loss_module, make_sac_agent
from nbv.rl.checkpoint import save_policy
from nbv.rl.config import TrainConfig
from nbv.rl.expert import EXPERT_KEY, label_keys
from nbv.rl.presets import PRESETS
from nbv.rl.train import mode_distance
from nbv.rl.unseen_map import UNSEEN_MAP_SIZE
from scenes.spec import SceneSet


def visit(env, actor, episodes: int, teacher: bool, desc: str, keys: list[str]) -> list[TensorDict]:
    """The states of `episodes` episodes flown by the teacher's actions or the actor's mode, each with the
    `keys` kept (the observation keys the actor reads, and the teacher's labels)."""
    states = []
    with torch.no_grad(), set_exploration_type(ExplorationType.DETERMINISTIC):
        for _ in tqdm(range(episodes), desc=desc, unit="episode"):
            td = env.reset()
            done = False
            while not done:
                states.append(td.select(*keys).clone())
                td = env.step(td.set("action", td[EXPERT_KEY]) if teacher else actor(td))
                done = bool(td["next", "done"])
                td = td["next"]
    return states


def buffer_states(path: Path, keys: list[str], last: int) -> list[TensorDict]:
    """The labelled states of a training checkpoint's replay buffer (its `last` newest; 0: all): the
    states SAC's own actor and exploration visited, each with the teacher's label."""
    stored = torch.load(path, weights_only=True, map_location="cpu")["buffer"]["_storage"]["_storage"]
    return [TensorDict({k: item[k] for k in keys}, []) for item in stored[-last if last else 0:]]


def seed_states(buffers: list[Path], keys: list[str], share: float,
                generator: torch.Generator) -> tuple[list[TensorDict], TensorDict | None]:
    """The labelled states of the `buffers` (each `CHECKPOINT[:LAST]`), shuffled, less a `share` of them
    held aside (stacked; None when none is)."""
    pooled: list[TensorDict] = []
    for spec in buffers:
        path, _, last = str(spec).partition(":")
        pooled += buffer_states(Path(path), keys, int(last or 0))
    if not pooled:
        return pooled, None
    order = torch.randperm(len(pooled), generator=generator).tolist()
    cut = int(round(share * len(pooled)))
    held = torch.stack([pooled[i] for i in order[:cut]]) if cut else None
    return [pooled[i] for i in order[cut:]], held


def train_config(preset: str, scenes: list[str], out: Path, privileged: bool = False) -> TrainConfig:
    """`nbv train --preset PRESET [--scene S ...] [--privileged-unseen] --out OUT`'s config (the given scenes
    replace the preset's), built from the presets themselves: a script does not import the command line."""
    config = PRESETS[preset]()
    config = replace(config, env=replace(config.env, privileged_unseen=privileged))
    if scenes:
        config = replace(config, env=replace(config.env, scenes=SceneSet(scene=tuple(scenes))))
    return replace(config, logger=replace(config.logger, out=out))


def strip_unseen(states: TensorDict) -> TensorDict:
    """The state(s) with the unseen map cut from the end of the Bag of Views vector (in place)."""
    return states.set(BOV_KEY, states[BOV_KEY][..., :-UNSEEN_MAP_SIZE])


def minibatch_passes(optimiser: torch.optim.Optimizer, data: TensorDict, epochs: int, batch: int,
                     generator: torch.Generator, loss: Callable[[TensorDict], torch.Tensor],
                     measured: Callable[[], dict]) -> list[dict]:
    """`epochs` passes of shuffled minibatch steps of `optimiser` on `loss` over `data`; per pass, the mean
    training loss and what `measured` returns after it."""
    passes = []
    for _ in tqdm(range(epochs), desc=f"fitting {len(data)} states", unit="pass"):
        order, losses = torch.randperm(len(data), generator=generator), []
        for start in range(0, len(data), batch):
            value = loss(data[order[start:start + batch]])
            optimiser.zero_grad()
            value.backward()
            optimiser.step()
            losses.append(value.item())
        passes.append({"train": float(sum(losses) / len(losses)), **measured()})
    return passes


def fit(actor, optimiser, data: TensorDict, held: TensorDict | None, epochs: int, batch: int,
        generator: torch.Generator) -> list[dict]:
    """`epochs` passes of minibatch Adam on `mode_distance` over `data`; per pass, the mean training loss and
    the loss on the `held` states (never fitted), if any."""
    def measured() -> dict:
        with torch.no_grad():
            return {"held": mode_distance(actor, held).item() if held is not None else None}

    return minibatch_passes(optimiser, data, epochs, batch, generator,
                            lambda part: mode_distance(actor, part), measured)


def arguments(argv: list[str]) -> argparse.Namespace:
    """The command line (module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--iterations", type=int, default=4)
    parser.add_argument("--episodes", type=int, default=60, help="episodes flown per iteration")
    parser.add_argument("--epochs", type=int, default=8, help="passes over the pooled states per iteration")
    parser.add_argument("--batch", type=int, default=64)
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--buffers", nargs="*", type=Path, default=[], metavar="CHECKPOINT[:LAST]",
                        help="training checkpoints whose replay buffers' labelled states seed the pool")
    parser.add_argument("--held", type=float, default=0.1, help="share of the seed states never fitted")
    parser.add_argument("--preset", choices=tuple(PRESETS), default="default", help="nbv train's preset")
    parser.add_argument("--privileged-unseen", action="store_true", help="the actor reads the unseen map")
    parser.add_argument("--strip-unseen", action="store_true", help="cut the unseen map from the buffers' "
                        "states (buffers of a --privileged-unseen run, fitted without it)")
    parser.add_argument("--scene", action="append", default=[], help="a training building (repeat; "
                        "given ones replace the preset's, as with nbv train)")
    args = parser.parse_args(argv)
    if args.privileged_unseen and args.strip_unseen:
        raise SystemExit("--strip-unseen fits an actor without the unseen map: not with --privileged-unseen")
    return args


def main(argv: list[str]) -> int:
    args = arguments(argv)
    config = train_config(args.preset, args.scene, args.out, args.privileged_unseen)
    if config.reward.imitation <= 0:
        raise SystemExit("the training env labels states with the teacher only with --imitation > 0")
    args.out.mkdir(parents=True, exist_ok=True)
    set_torch_threads(config.collector.threads)
    torch.manual_seed(args.seed)
    env = make_environment(config.env, 1, args.seed, config.reward) if args.iterations else None
    actor, critic = make_sac_agent(config.env, config.network)
    loss_module, _ = make_loss_module(actor, critic, config.optim)  # its state dict shares the actor's
    optimiser = torch.optim.Adam(actor.parameters(), lr=args.lr)
    generator = torch.Generator().manual_seed(args.seed)
    keys = [*actor.in_keys, *label_keys(config.reward)]
    pooled, held = seed_states(args.buffers, keys, args.held, generator)
    if args.strip_unseen and pooled:
        pooled = [strip_unseen(state) for state in pooled]
        held = None if held is None else strip_unseen(held)
    log = []
    start = time.perf_counter()
    if pooled:
        cut = 0 if held is None else len(held)
        log.append({"iteration": "buffers", "states": len(pooled), "held_states": cut,
                    "passes": fit(actor, optimiser, torch.stack(pooled), held, args.epochs, args.batch,
                                  generator), "seconds": round(time.perf_counter() - start, 1)})
        print(log[-1], flush=True)
    for iteration in range(args.iterations):
        teacher = iteration == 0 and not pooled  # with seed states the student flies from the start
        new = visit(env, actor, args.episodes, teacher, f"iteration {iteration}", keys)
        with torch.no_grad():
            on_policy = mode_distance(actor, torch.stack(new)).item()
        pooled += new
        log.append({"iteration": iteration, "states": len(pooled), "teacher_flies": teacher,
                    "loss_on_new_states": on_policy,
                    "passes": fit(actor, optimiser, torch.stack(pooled), held, args.epochs, args.batch,
                                  generator), "seconds": round(time.perf_counter() - start, 1)})
        print(log[-1], flush=True)
    counters = {"frames": len(pooled), "updates": args.iterations * args.epochs}
    save_policy(args.out / "policy.pt", json.dumps(config_record(config)), loss_module.state_dict(), counters)
    write_json(args.out / "config.json", config_record(config))
    write_json(args.out / "dagger.json", portable_record({
        "commit": git_commit(), "command": ["scripts/dagger.py", *argv], "iterations": log}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
