"""The dataclass -> argparse generator: docstrings become help, types become parsers."""

import argparse
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import pytest

from nbv.cli.config_args import add_config_arguments, config_from_args, field_docs, positional, repeated


@dataclass(frozen=True)
class ToyConfig:
    """A config exercising every supported field type."""

    target: str = positional()
    """What to work on."""
    out: Path = None
    """Where results go."""
    count: int = 3
    """How many."""
    mode: Literal["fast", "slow"] = "fast"
    """Which way."""
    sizes: tuple[int, ...] = (5, 7)
    """Several sizes."""
    tags: tuple[str, ...] = repeated(default=("a",))
    """Repeatable tag."""
    limit: float | None = None
    """Optional cap."""
    verbose: bool = False
    """Talk more."""


def parse(argv):
    parser = argparse.ArgumentParser()
    add_config_arguments(parser, ToyConfig)
    return config_from_args(ToyConfig, parser.parse_args(argv)), parser


def test_field_docstrings_become_help():
    assert field_docs(ToyConfig)["sizes"] == "Several sizes."
    _, parser = parse(["x", "--out", "o"])
    text = parser.format_help()
    assert "How many. (default: 3)" in text and "Several sizes. (default: 5 7)" in text


def test_values_are_parsed_into_the_dataclass():
    config, _ = parse(["bldg", "--out", "o", "--count", "4", "--mode", "slow", "--sizes", "9", "11",
                       "--tags", "x", "--tags", "y", "--limit", "2.5", "--verbose"])
    assert config == ToyConfig("bldg", Path("o"), 4, "slow", (9, 11), ("x", "y"), 2.5, True)


def test_defaults_and_required_options():
    config, _ = parse(["bldg", "--out", "o"])
    assert (config.count, config.sizes, config.tags) == (3, (5, 7), ("a",))
    assert (config.limit, config.verbose) == (None, False)
    with pytest.raises(SystemExit):
        parse(["bldg"])  # --out has no default
    with pytest.raises(SystemExit):
        parse(["bldg", "--out", "o", "--mode", "medium"])
