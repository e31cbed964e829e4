"""Training checkpoints and policy files: written atomically, read with `torch.load(weights_only=True)`.

A policy file (`policy.pt`, a few MB, written beside every checkpoint) holds
what planning needs: the run's config as JSON, the actor's state dict and the
counters. A checkpoint is a plain dict of tensors, numbers, strings and containers of
them (nothing that needs pickle's arbitrary code): the run's config as JSON,
the state dicts of the loss module (actor, twin critics, targets), optimisers
and replay buffer, the counters, the random states of torch, NumPy and Python,
and, for a one-worker run, the env's runtime state. Every file carries the SHA-256 of its tensors
(`nbv.rl.archive`), checked on load after its zip entries' sizes and CRCs.
Loading a truncated, corrupt or foreign file, or one whose config the run
cannot continue, raises `CheckpointError` naming the file and the reason; a
file written before the checksum (its CRCs still checked) loads with a warning.
"""

from __future__ import annotations

import json
import pickle
import random
import warnings
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import torch

from common.io import atomic_path
from nbv.rl.archive import CHECKSUM_KEY, ArchiveError, check_archive, nonfinite_weights, tensor_checksum
from nbv.rl.config import upgrade_record

FORMAT = "nbv-sac-checkpoint"
VERSION = 1
REQUIRED = ("format", "version", "config", "loss", "optim_actor", "optim_critic", "buffer", "counters", "rng")
POLICY_FORMAT = "nbv-sac-policy"
POLICY_REQUIRED = ("format", "version", "config", "actor", "counters")
ACTOR_PREFIX = "actor_network_params."
"""Where the actor's weights sit in a checkpoint's loss state dict."""


class CheckpointError(ValueError):
    """A checkpoint is missing, corrupt, of another format, or does not fit the run loading it."""


def rng_state() -> dict[str, Any]:
    """The global random states of torch, NumPy and Python, as weights_only-loadable values."""
    kind, keys, pos, has_gauss, gauss = np.random.get_state()
    return {"torch": torch.get_rng_state(),
            "numpy": {"kind": kind, "keys": torch.from_numpy(keys.astype(np.int64)), "pos": int(pos),
                      "has_gauss": int(has_gauss), "gauss": float(gauss)},
            "python": random.getstate()}


def set_rng_state(state: dict[str, Any]) -> None:
    """Restore what `rng_state` returned."""
    torch.set_rng_state(state["torch"])
    n = state["numpy"]
    keys = n["keys"].numpy().astype(np.uint32)
    np.random.set_state((n["kind"], keys, n["pos"], n["has_gauss"], n["gauss"]))
    version, internal, gauss = state["python"]
    random.setstate((version, tuple(internal), gauss))


def seed_everything(seed: int) -> None:
    """Seed torch, NumPy and Python's global generators."""
    torch.manual_seed(seed)
    np.random.seed(seed)
    random.seed(seed)


def save_checkpoint(path: str | Path, state: dict[str, Any], kind: str = FORMAT) -> Path:
    """Write `state` (tagged with format `kind` and version) atomically to `path`."""
    path = Path(path)
    doc = {"format": kind, "version": VERSION, **state}
    with atomic_path(path) as tmp:
        torch.save({**doc, CHECKSUM_KEY: tensor_checksum(doc)}, tmp)
    return path


def load_checkpoint(path: str | Path, kinds: tuple[str, ...] = (FORMAT,)) -> dict[str, Any]:
    """Read and validate a `save_checkpoint` file of one of `kinds` (weights_only: no code runs)."""
    path = Path(path)
    if not path.is_file():
        raise CheckpointError(f"checkpoint {path} not found")
    try:
        check_archive(path)
        state = torch.load(path, map_location="cpu", weights_only=True)
    except ArchiveError as err:
        raise CheckpointError(f"checkpoint {path}: {err}") from err
    except (RuntimeError, EOFError, OSError, zipfile.BadZipFile, pickle.UnpicklingError, ValueError) as err:
        raise CheckpointError(f"checkpoint {path} is corrupt or not a checkpoint: {err}") from err
    if not isinstance(state, dict) or state.get("format") not in kinds:
        names = " or ".join({FORMAT: "an nbv SAC checkpoint", POLICY_FORMAT: "an nbv policy file"}[k]
                            for k in kinds)
        raise CheckpointError(f"checkpoint {path} is not {names}")
    if state.get("version") != VERSION:
        raise CheckpointError(f"checkpoint {path} has version {state.get('version')}, "
                              f"this toolkit reads {VERSION}")
    required = POLICY_REQUIRED if state["format"] == POLICY_FORMAT else REQUIRED
    missing = [key for key in required if key not in state]
    if missing:
        raise CheckpointError(f"checkpoint {path} lacks {', '.join(missing)}")
    _check_checksum(state, path)
    return state


def _check_checksum(state: dict[str, Any], path: Path) -> None:
    """Refuse a file whose tensors differ from the checksum it carries; warn for one written without."""
    stored = state.get(CHECKSUM_KEY)
    if stored is None:
        warnings.warn(f"checkpoint {path} carries no tensor checksum (written before the toolkit stored "
                      f"one); its zip CRCs were checked. Re-save it to add one", stacklevel=3)
    elif stored != tensor_checksum(state):
        raise CheckpointError(f"checkpoint {path} is corrupt: its tensors do not match the checksum it "
                              f"carries (damaged bytes?); use an intact copy")


def save_policy(path: str | Path, config: str, loss_state: dict[str, Any], counters: dict[str, int]) -> Path:
    """Write a policy file: the run config (JSON text), the actor weights out of the loss state, counters."""
    return save_checkpoint(path, {"config": config, "actor": actor_weights(loss_state), "counters": counters},
                           POLICY_FORMAT)


def copy_policy(source: str | Path, dest: str | Path, config: dict[str, Any]) -> Path:
    """Write the actor and counters of the policy file `source` to `dest` under another run `config`."""
    state = load_checkpoint(source, (POLICY_FORMAT,))
    return save_checkpoint(dest, {"config": json.dumps(config), "actor": state["actor"],
                                  "counters": state["counters"]}, POLICY_FORMAT)


def actor_weights(loss_state: dict[str, Any]) -> dict[str, torch.Tensor]:
    """The actor's state dict out of a SAC loss module's state dict."""
    return {k[len(ACTOR_PREFIX):]: v for k, v in loss_state.items() if k.startswith(ACTOR_PREFIX)}


def load_policy(path: str | Path) -> tuple[dict[str, Any], dict[str, torch.Tensor]]:
    """The run config and actor weights of a policy file or a training checkpoint."""
    state = load_checkpoint(path, (POLICY_FORMAT, FORMAT))
    config = checkpoint_config(state, path)
    if state["format"] == POLICY_FORMAT:
        weights = state["actor"]
    else:
        loss = state["loss"]
        weights = actor_weights(loss) if isinstance(loss, dict) else loss
    bad = nonfinite_weights(weights) if isinstance(weights, dict) else []
    if bad:
        raise CheckpointError(f"checkpoint {path}: actor weights {', '.join(bad[:3])}"
                              f"{' and more' if len(bad) > 3 else ''} hold NaN or infinite values "
                              f"(a diverged run?); use an earlier checkpoint")
    return config, weights


def checkpoint_config(state: dict[str, Any], path: str | Path = "checkpoint") -> dict[str, Any]:
    """The run config stored in a checkpoint, as a nested dict in today's layout (`upgrade_record`: a
    record from before a key moved group reads as if written now); CheckpointError naming `path` if not
    one."""
    try:
        config = json.loads(state["config"])
    except (TypeError, ValueError, RecursionError) as err:
        raise CheckpointError(f"checkpoint {path}: its config is not JSON text: {err}") from err
    if not isinstance(config, dict):
        raise CheckpointError(f"checkpoint {path}: its config must be a JSON object, "
                              f"got {type(config).__name__}")
    return upgrade_record(config)


def check_compatible(path: str | Path, saved: dict[str, Any], current: dict[str, Any],
                     free: tuple[str, ...]) -> None:
    """Raise `CheckpointError` listing every setting that differs, except the `free` (dotted) ones."""
    diffs = [f"{key}: checkpoint {a!r}, now {b!r}" for key, a, b in _diff(saved, current) if key not in free]
    if diffs:
        raise CheckpointError(f"checkpoint {path} does not match this run's settings ({'; '.join(diffs)})")


def _diff(a: Any, b: Any, prefix: str = "") -> list[tuple[str, Any, Any]]:
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for key in sorted(set(a) | set(b)):
            out += _diff(a.get(key), b.get(key), f"{prefix}{key}.")
        return out
    return [] if a == b else [(prefix.rstrip("."), a, b)]
