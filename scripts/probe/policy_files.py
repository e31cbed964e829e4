"""Part 6: policy and checkpoint files for `nbv plan --planner policy:FILE`."""

from __future__ import annotations

import json
import os
import zipfile
from collections.abc import Callable
from pathlib import Path

from probe.harness import ENV, Case, Result

PLAN = "nbv plan test_building --planner policy:{f} --views 3 --no-full-scan $CAM --out o"


def policy(name: str, edit: Callable[[dict], None], checksum: bool = True) -> Callable[[Path], None]:
    """Setup: the shipped policy loaded, edited, saved as `name` (its tensor checksum recomputed when
    `checksum`, so the edit itself is what the loader meets)."""

    def setup(folder: Path) -> None:
        import torch

        from nbv.rl.archive import tensor_checksum

        state = torch.load(ENV["POLICY"], map_location="cpu", weights_only=True)
        edit(state)
        if checksum:
            state["checksum"] = tensor_checksum({k: v for k, v in state.items() if k != "checksum"})
        torch.save(state, folder / name)

    return setup


def config_edit(path: str, value) -> Callable[[dict], None]:
    """Set the policy's recorded config at dotted `path` to `value`."""

    def edit(state: dict) -> None:
        record = json.loads(state["config"])
        node, keys = record, path.split(".")
        for key in keys[:-1]:
            node = node[key]
        node[keys[-1]] = value
        state["config"] = json.dumps(record)

    return edit


def zeroed(folder: Path) -> None:
    """F20: 64 zeroed bytes in the middle of the shipped policy."""
    data = bytearray(Path(ENV["POLICY"]).read_bytes())
    middle = len(data) // 2
    data[middle : middle + 64] = bytes(64)
    (folder / "bad.pt").write_bytes(data)


def zip_bomb(folder: Path) -> None:
    """F23: a ~2 MB zip whose archive/data.pkl inflates to 2 GiB, named .pt."""
    with zipfile.ZipFile(folder / "bomb.pt", "w", zipfile.ZIP_DEFLATED, compresslevel=9) as archive:
        with archive.open("archive/data.pkl", "w", force_zip64=True) as entry:
            block = bytes(2**24)
            for _ in range(128):
                entry.write(block)
        archive.writestr("archive/version", "3\n")


def pickle_bomb(folder: Path) -> None:
    """A code-running pickle in a torch zip (must not run: no PWNED file)."""
    import torch

    class Evil:
        def __reduce__(self):
            return (os.system, (f"touch {folder}/PWNED",))

    torch.save({"format": "nbv-sac-policy", "evil": Evil()}, folder / "evil.pt")


def no_pwned(folder: Path, result: Result) -> tuple[str, str] | None:
    """Check: the pickle's code did not run."""
    return ("silent", "PWNED exists: the pickle ran") if (folder / "PWNED").exists() else None


def _nan_actor(state: dict) -> None:
    for tensor in state["actor"].values():
        if tensor.is_floating_point():
            tensor.fill_(float("nan"))


# Part 6: F20-F23 and the passing policy-file cases for `nbv plan --planner policy:FILE`.
trunc = "head -c $(( $(stat -c %s $POLICY) / 2 )) $POLICY > half.pt"
PART6 = [
    Case(6, "F20-zeroed-bytes", PLAN.format(f="bad.pt"), words=("bad.pt",), setup=zeroed, timeout=150),
    Case(
        6,
        "F21-action-mode-teleport",
        PLAN.format(f="tp.pt"),
        words=("tp.pt", "action_mode"),
        setup=policy("tp.pt", config_edit("env.action_mode", "teleport")),
        timeout=150,
    ),
    Case(
        6,
        "F22-nan-weights",
        PLAN.format(f="nan.pt"),
        words=("nan.pt",),
        setup=policy("nan.pt", _nan_actor),
        timeout=150,
    ),
    Case(
        6,
        "F23-zip-bomb",
        PLAN.format(f="bomb.pt"),
        words=("bomb.pt",),
        setup=zip_bomb,
        memory=2**30,
        timeout=150,
    ),
    Case(6, "truncated-half", PLAN.format(f="half.pt"), words=("half.pt",), setup=trunc, timeout=150),
    Case(6, "empty-file", PLAN.format(f="empty.pt"), words=("empty.pt",), setup="touch empty.pt"),
    Case(6, "directory", PLAN.format(f="dir.pt"), words=("dir.pt",), setup="mkdir dir.pt"),
    Case(6, "fifo", PLAN.format(f="fifo.pt"), words=("fifo.pt",), setup="mkfifo fifo.pt", timeout=60),
    Case(6, "dev-null", PLAN.format(f="/dev/null"), words=("/dev/null",)),
    Case(6, "dev-zero", PLAN.format(f="/dev/zero"), words=("/dev/zero",), timeout=60, memory=2**30),
    Case(
        6,
        "code-running-pickle",
        PLAN.format(f="evil.pt"),
        words=("evil.pt",),
        setup=pickle_bomb,
        check=no_pwned,
    ),
    Case(
        6,
        "config-channels-64",
        PLAN.format(f="c.pt"),
        words=("c.pt",),
        setup=policy("c.pt", config_edit("network.channels", 64)),
    ),
    Case(
        6,
        "version-2",
        PLAN.format(f="v.pt"),
        words=("v.pt",),
        setup=policy("v.pt", lambda s: s.update(version=2)),
    ),
    Case(
        6,
        "foreign-state-dict",
        PLAN.format(f="f.pt"),
        words=("f.pt",),
        setup=policy("f.pt", lambda s: [s.pop(k) for k in list(s) if k != "actor"], checksum=False),
    ),
    Case(
        6,
        "no-checksum-warns",
        PLAN.format(f="nc.pt"),
        expect="warn",
        words=("checksum",),
        setup=policy("nc.pt", lambda s: s.pop("checksum"), checksum=False),
        timeout=150,
    ),
    Case(6, "shipped-policy", PLAN.format(f="$POLICY"), expect="ok", timeout=150),
]


def part6() -> list[Case]:
    """Part 6: F20-F23 and the passing policy-file cases for `nbv plan --planner policy:FILE`."""
    return list(PART6)


