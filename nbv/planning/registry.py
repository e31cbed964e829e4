"""Every planner by name: one `PlannerEntry` each, in `PLANNERS` (docs/rl.md §10).

Light on purpose: a factory is named as "module:callable" and imported only when a planner is made, so
the command line lists the planners without loading torch or a renderer. Every list of planner names
(`nbv plan --help`, the study drivers' defaults, README.md, docs/rl.md §10) is generated from here, so
adding a planner is its own file plus one entry below.

A spec names a planner, optionally with a checkpoint: `policy:runs/x/policy.pt`. An entry that takes a
checkpoint (`checkpoint=True`) runs the shipped policy (`SHIPPED_POLICY`) without one. An entry with an
`argument` takes that instead (`orbit:2.0,5`); without one it runs its shipped choice.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from nbv.planning.base import Planner
    from nbv.planning.config import PlanSettings

SHIPPED_POLICY = Path(__file__).with_name("shipped") / "policy.pt"
"""The policy of the default `nbv train` command, shipped with the toolkit (its config, metrics log and
learning curves beside it): what `policy` and `policy-sample` without a checkpoint use."""
SHIPPED_PAPER_POLICY = SHIPPED_POLICY.parent / "paper" / "policy.pt"
"""The policy of `nbv train --preset paper` (the paper's Table 1 method, README and config beside it): what
`policy-paper` flies, so every study can show the paper's method beside the default (issue 26)."""
SHIPPED_POLICIES = ("policy", "policy-paper")
"""The shipped policies as planner specs, the default first: what `nbv online` and `nbv tables` (Fig. 1 /
Fig. 7) report side by side unless told otherwise."""


@dataclass(frozen=True)
class PlannerEntry:
    """One planner: its name, what it is, how to make it, and what a study needs to know of it."""

    name: str
    """The spec's name, e.g. "greedy" (`--planner greedy`)."""
    summary: str
    """One line: the `--help` and docs text."""
    factory: str
    """"module:callable", imported lazily; callable(settings: PlanSettings, seed: int,
    checkpoint: str | None) -> Planner (the checkpoint, or the `argument`, after the ':'; None without)."""
    settings: tuple[str, ...] = ()
    """The `PlanSettings` fields it reads (e.g. ("candidates", "occupancy"))."""
    reads_truth: bool = False
    """It uses the true mesh (the oracle): an upper bound, not a planner a UAV has."""
    prefixes: bool = True
    """Its plan for n views starts with its plan for fewer (sequential); False: planned afresh per budget
    (circle, oracle) or not cut at all (hemisphere)."""
    checkpoint: bool = False
    """It takes ':CHECKPOINT' (policy, policy-sample); without one the shipped policy."""
    budget: bool = True
    """One of the budget study's default planners (False: the fixed hemisphere scan, the policy's sampled
    twin)."""
    argument: str | None = None
    """What a ':ARG' after the name gives, as the help writes it (e.g. "R,ELEVATION"); None: none (a
    checkpoint entry takes CHECKPOINT)."""
    compared: bool = False
    """One of the baselines `nbv compare` and `nbv online` run by default."""
    tuned: bool = False
    """A fixed pattern chosen on the training buildings (the tuned orbits): the demo's online half flies it
    beside the policy and random views."""
    depth_option: bool = False
    """Issue 26's named depth option: a planner that looks at the depth it measures (the policies read only
    images and poses). `nbv online` holds it to the policies' checks in a column of its own, and the demo
    flies it beside them."""
    image_option: bool = False
    """A planner with a rule of its own (not learnt) that reads only images and the poses flown, as the
    policies do (`lookahead-stereo`): `nbv online` reports it with the policies, held to every check, and
    the demo flies it beside them."""

    @property
    def spec(self) -> str:
        """How the spec is written: the name, with `[:CHECKPOINT]` (or `[:ARGUMENT]`) when it takes one."""
        takes = "CHECKPOINT" if self.checkpoint else self.argument
        return f"{self.name}[:{takes}]" if takes else self.name


PLANNERS: tuple[PlannerEntry, ...] = (
    PlannerEntry("random", "viewpoints uniform in the allowed ranges (seeded)",
                 "nbv.planning.planners:random_planner", settings=("links", "candidates"), compared=True),
    PlannerEntry("circle", "evenly spaced azimuths at the middle radius and elevation",
                 "nbv.planning.planners:circle_planner", prefixes=False, compared=True),
    PlannerEntry("orbit", "one ring: evenly spaced azimuths from the start view's azimuth at a fixed radius "
                 "and elevation, the ring chosen on the training buildings (nbv/planning/shipped/orbit.json, "
                 "scripts/choose_orbit.py), or orbit:R,ELEVATION (metres, degrees)",
                 "nbv.planning.orbit:orbit_planner", prefixes=False, argument="R,ELEVATION", compared=True,
                 tuned=True),
    PlannerEntry("orbit2", "two rings flown one after the other in the same direction, the views split "
                 "half-half (the first ring takes the odd one), the second's azimuths half a step on: the "
                 "pair chosen on the training buildings, or orbit2:R1,E1,R2,E2",
                 "nbv.planning.orbit:orbit2_planner", prefixes=False, argument="R1,E1,R2,E2", compared=True,
                 tuned=True),
    PlannerEntry("greedy", "greedy Bag of Views: from the start view, render K (--candidates) random "
                 "candidates per step, move to the one of highest Bag of Views reward (no learning)",
                 "nbv.planning.planners:greedy_planner", settings=("candidates", "bov", "links"),
                 compared=True),
    PlannerEntry("hemisphere", "the full hemisphere scan at the middle radius (288 views with the default "
                 "camera)", "nbv.planning.planners:hemisphere_planner", prefixes=False, budget=False),
    PlannerEntry("infogain", "volumetric information gain (model-free, from depth): move to the one of K "
                 "random candidates (greedy's stream) that would see the most unknown voxels of an occupancy "
                 "grid carved from the depth of the views flown to",
                 "nbv.planning.infogain:infogain_planner", settings=("candidates", "occupancy", "links")),
    PlannerEntry("lookahead", "the training teacher's look-ahead on measured depth (issue 26's depth "
                 "option): the orbit step whose next three views would first reach the most unknown voxels "
                 "of an occupancy grid fused from the depth flown, less 0.07 a metre flown (lookahead:W "
                 "another weight)", "nbv.planning.lookahead:lookahead_planner", argument="W", budget=False,
                 depth_option=True),
    PlannerEntry("lookahead-stereo", "the same look-ahead on what a camera alone measures, flying a "
                 "pilot's orbit: each step 27.7 to 55.4 degrees forward round the target, its radius and "
                 "elevation chosen with every view still to take as one route, planned again at each view; "
                 "the grid fused from plane-sweep stereo depth of each "
                 "view and a second frame 0.25 m back along its orbit (reads images and poses, as the "
                 "policies do), valuing the sides of surface it has not yet measured (rays over 60 degrees "
                 "down measure none), less 0.1 a metre and 2 a metre more past a battery of 13 m, one more a "
                 "view past 13 views (lookahead-stereo:W another weight, lookahead-stereo:W,M or :,M a fixed "
                 "battery of M metres)",
                 "nbv.planning.lookahead:stereo_lookahead_planner", settings=("blank_images",),
                 argument="W,M", prefixes=False, image_option=True),
    PlannerEntry("policy", "a trained actor (a `nbv train` checkpoint.pt or policy.pt; none: the shipped "
                 "policy) from the start view, acting on its distribution's mode",
                 "nbv.planning.policy:policy_planner", settings=("blank_images",), checkpoint=True),
    PlannerEntry("policy-sample", "the same, acting on seeded draws from the distribution",
                 "nbv.planning.policy:sampled_policy_planner", settings=("blank_images",), checkpoint=True,
                 budget=False),
    PlannerEntry("policy-paper", "the paper's method: the actor `nbv train --preset paper` trained "
                 "(absolute actions, the Bag of Views reward alone; nbv/planning/shipped/paper/), from the "
                 "start view, acting on its distribution's mode",
                 "nbv.planning.policy:paper_policy_planner", settings=("blank_images",)),
    PlannerEntry("oracle", "at least every other budget planner on the reported coverage (TSDF, of the true "
                 "surface): the best, on that measure, of each one's views and of its own greedy pick over "
                 "them, the start view and the views an ideal sensor sees most from (a 756-view lattice)",
                 "nbv.planning.oracle:oracle_planner", settings=("candidates", "bov", "occupancy", "recon",
                                                                 "metrics"), reads_truth=True,
                 prefixes=False),
)
"""The shipped planners, in the order every generated list gives them."""

_REGISTERED: dict[str, PlannerEntry] = {e.name: e for e in PLANNERS}


def register(planner: PlannerEntry) -> PlannerEntry:
    """Add a planner (a plug-in's, or a test's); a ValueError if its name is taken or holds a ':'."""
    if ":" in planner.name or not planner.name:
        raise ValueError(f"a planner name must be non-empty and hold no ':', got {planner.name!r}")
    if planner.name in _REGISTERED:
        raise ValueError(f"planner {planner.name!r} is registered already")
    _REGISTERED[planner.name] = planner
    return planner


def unregister(name: str) -> None:
    """Remove a registered planner (a test's toy, afterwards)."""
    _REGISTERED.pop(name)


def entries() -> tuple[PlannerEntry, ...]:
    """Every planner, the shipped ones first in `PLANNERS` order, then the registered ones."""
    return tuple(_REGISTERED.values())


def entry(spec: str) -> PlannerEntry:
    """The entry of a spec (`name`, `name:CHECKPOINT` or `name:ARGUMENT`); a ValueError listing every
    planner if unknown."""
    name, sep, _ = spec.partition(":")
    found = _REGISTERED.get(name)
    if found is None or (sep and not (found.checkpoint or found.argument)):
        raise ValueError(f"unknown planner {spec!r}; use {', '.join(e.spec for e in entries())}")
    return found


def split_spec(spec: str) -> tuple[PlannerEntry, str | None]:
    """The entry of a spec and its checkpoint or argument (None where none is named)."""
    found = entry(spec)
    _, sep, checkpoint = spec.partition(":")
    return found, checkpoint if sep else None


def make_planner(spec: str, settings: PlanSettings, seed: int = 0) -> Planner:
    """The planner a spec names, under the plan's settings and seed (its factory imported now)."""
    found, checkpoint = split_spec(spec)
    module, _, attribute = found.factory.partition(":")
    factory = importlib.import_module(module)
    for part in attribute.split("."):
        factory = getattr(factory, part)
    return factory(settings, seed, checkpoint)


def planner_label(spec: str) -> str:
    """A short, file-name-safe label of a planner spec: a policy is named after its run folder."""
    found, checkpoint = split_spec(spec)
    if found.checkpoint:
        return f"{found.name}-{Path(checkpoint or SHIPPED_POLICY).resolve().parent.name}"  # policy-shipped
    if checkpoint:
        return f"{found.name}-{checkpoint.replace(',', '_')}"  # orbit:2.0,5 -> orbit-2.0_5
    return spec


def planner_help() -> str:
    """The `--planner` help text: every planner with its summary."""
    lines = [f"{e.spec}: {e.summary}" + (" [reads the true mesh]" if e.reads_truth else "")
             for e in entries()]
    return "One of:\n" + "\n".join(f"- {line}" for line in lines)


def planner_specs() -> str:
    """Every spec, comma-separated, the oracle-like ones marked: for the study drivers' `--help`."""
    return ", ".join(e.spec + (" (reads the true mesh: an upper bound)" if e.reads_truth else "")
                     for e in entries())


def planner_choices() -> str:
    """The specs in braces, as the README's synopsis writes them: {random,circle,...}."""
    return "{" + ",".join(e.spec for e in entries()) + "}"


def docs_table() -> str:
    """The Markdown table of planners in docs/rl.md §10 (a test keeps the page equal to it)."""
    rows = [f"| `{e.spec}` | {'**upper bound, reads the true mesh**: ' if e.reads_truth else ''}"
            f"{e.summary} |" for e in entries()]
    return "\n".join(["| spec | planner |", "| --- | --- |", *rows])


def budget_planners() -> tuple[str, ...]:
    """The budget study's default planners: every entry with `budget` set, in registry order."""
    return tuple(e.name for e in entries() if e.budget)


def compared_planners() -> tuple[str, ...]:
    """The default baselines of `nbv compare` and `nbv online`: every entry with `compared` set."""
    return tuple(e.name for e in entries() if e.compared)


def tuned_planners() -> tuple[str, ...]:
    """The fixed patterns chosen on the training buildings: every entry with `tuned` set."""
    return tuple(e.name for e in entries() if e.tuned)


def depth_planners() -> tuple[str, ...]:
    """The named depth options (`nbv online --depth-options`, the demo's online half): every entry with
    `depth_option` set."""
    return tuple(e.name for e in entries() if e.depth_option)


def image_planners() -> tuple[str, ...]:
    """The image-only planners with rules of their own (`nbv online`'s policies after the shipped ones, the
    demo's online half): every entry with `image_option` set."""
    return tuple(e.name for e in entries() if e.image_option)


def replanned() -> tuple[str, ...]:
    """Planners whose shorter plans are not prefixes of their longer ones: planned at every budget."""
    return tuple(e.name for e in entries() if not e.prefixes)
