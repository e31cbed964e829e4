"""The planner registry: one entry per planner, every list of planner names generated from it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from nbv.cli import main
from nbv.planning import registry
from nbv.planning.base import Planner
from nbv.planning.config import PlanConfig, PlanSettings
from nbv.planning.registry import PlannerEntry, entries, entry, make_planner, planner_label, register
from render.viewpoint import Viewpoint
from scenes.spec import SceneSpec

ROOT = Path(__file__).resolve().parents[3]
SHIPPED = ("random", "circle", "orbit", "orbit2", "greedy", "hemisphere", "infogain", "lookahead",
           "lookahead-stereo", "policy", "policy-sample", "policy-paper", "oracle")


class ToyPlanner(Planner):
    """Flies a fixed arc: a planner defined outside the toolkit, registered by a test."""

    name = "toy"

    def __init__(self, radius: float) -> None:
        self.radius = radius

    def plan(self, env, views: int | None) -> list[Viewpoint]:
        return [Viewpoint(self.radius, 0.5 * k, 0.4) for k in range(views or 3)]


def toy_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> ToyPlanner:
    return ToyPlanner(2.0 + 0.01 * settings.candidates)


@pytest.fixture
def toy():
    found = register(PlannerEntry("toy", "a fixed arc of views (a test's planner)",
                                  f"{__name__}:toy_planner", settings=("candidates",)))
    yield found
    registry.unregister("toy")


def test_every_shipped_planner_has_one_entry_and_a_factory_that_makes_it():
    assert [e.name for e in entries()] == list(SHIPPED)
    for name in ("random", "circle", "greedy", "hemisphere", "infogain", "lookahead", "oracle"):
        assert isinstance(make_planner(name, PlanSettings()), Planner)
    assert [e.name for e in entries() if e.reads_truth] == ["oracle"]
    assert [e.name for e in entries() if e.checkpoint] == ["policy", "policy-sample"]
    paper = make_planner("policy-paper", PlanSettings())  # the paper preset's shipped actor, on its mode
    assert paper.checkpoint == registry.SHIPPED_PAPER_POLICY and not paper.sample
    assert planner_label("policy-paper") == "policy-paper"
    with pytest.raises(ValueError, match="unknown planner"):
        entry("policy-paper:runs/x/policy.pt")  # it flies the shipped file and takes none


def test_settings_reach_the_planner_and_specs_resolve():
    assert make_planner("greedy", PlanSettings(candidates=3), seed=4).candidates == 3
    assert make_planner("infogain", PlanSettings(candidates=5)).candidates == 5
    assert entry("policy:runs/x/policy.pt") is entry("policy")
    assert planner_label("policy-sample:runs/x/policy.pt") == "policy-sample-x"
    assert planner_label("policy") == "policy-shipped" and planner_label("circle") == "circle"


@pytest.mark.parametrize("spec", ["best", "greedy:checkpoint.pt", ""])
def test_an_unknown_spec_names_every_planner(spec):
    with pytest.raises(ValueError, match="unknown planner") as err:
        entry(spec)
    assert all(name in str(err.value) for name in SHIPPED)
    with pytest.raises(ValueError, match="unknown planner"):
        PlanConfig(scene=SceneSpec(scene="test_building"), planner=spec, out=Path("x"))


def test_names_are_unique_and_plain():
    with pytest.raises(ValueError, match="registered already"):
        register(PlannerEntry("greedy", "again", "x:y"))
    with pytest.raises(ValueError, match="no ':'"):
        register(PlannerEntry("a:b", "colon", "x:y"))


def test_the_docs_list_the_registrys_planners():
    rl = (ROOT / "docs" / "rl.md").read_text()
    begin, end = rl.index("<!-- planners: generated"), rl.index("<!-- planners: end -->")
    assert rl[begin:end].split("\n", 1)[1].strip() == registry.docs_table()
    synopsis = f"nbv plan SCENE --planner {registry.planner_choices()} --out DIR"
    assert synopsis in (ROOT / "README.md").read_text()


def test_the_study_lists_come_from_the_registry():
    from nbv.experiments.budget import PLANNERS, REPLANNED

    assert PLANNERS == ("random", "circle", "orbit", "orbit2", "greedy", "infogain", "lookahead-stereo",
                        "policy", "policy-paper", "oracle")
    assert REPLANNED == ("circle", "orbit", "orbit2", "lookahead-stereo", "oracle")


def test_a_registered_planner_is_in_the_help_and_plans_end_to_end(toy, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path / "cache"))
    assert main(["plan", "--help"]) == 0
    words = " ".join(capsys.readouterr().out.replace("│", " ").split())  # tyro wraps the text in a box
    assert "- toy: a fixed arc of views (a test's planner)" in words and "- oracle: at least every" in words
    out = tmp_path / "plan"
    tiny = ["--width", "64", "--height", "48", "--spp", "1", "--no-full-scan", "--metric-points", "3000",
            "--voxel-size-m", "0.01"]
    args = ["plan", "test_building", "--planner", "toy", "--views", "3", "--candidates", "50", *tiny,
            "--out", str(out)]
    assert main(args) == 0
    plan = json.loads((out / "plan.json").read_text())
    assert plan["planner"] == "toy" and plan["views"] == 3  # the settings reached its factory: R = 2.5
    assert plan["viewpoints"] == [[2.5, 0.0, 0.4], [2.5, 0.5, 0.4], [2.5, 1.0, 0.4]]
    assert 0.0 < plan["gt"]["coverage"] <= 1.0
