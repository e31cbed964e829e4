"""Command-line options generated from frozen config dataclasses.

Each field becomes `--field-name` (or a positional argument when its metadata
says `positional=True`); its attribute docstring becomes the `--help` text, so
the config class is the documentation. Supported field types: int, float, str,
Path, bool (`--flag/--no-flag`), Literal choices, tuples (`nargs='+'`) and
`X | None`.
"""

from __future__ import annotations

import argparse
import ast
import dataclasses
import inspect
import textwrap
import types
import typing
from functools import cache
from pathlib import Path
from typing import Any, TypeVar

T = TypeVar("T")


@cache
def field_docs(cls: type) -> dict[str, str]:
    """Attribute docstrings (the string literal right after each field) of a dataclass."""
    docs: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        if not dataclasses.is_dataclass(klass):
            continue
        tree = ast.parse(textwrap.dedent(inspect.getsource(klass)))
        body = tree.body[0].body
        for node, nxt in zip(body, body[1:]):
            if (isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name)
                    and isinstance(nxt, ast.Expr) and isinstance(nxt.value, ast.Constant)
                    and isinstance(nxt.value.value, str)):
                docs[node.target.id] = " ".join(nxt.value.value.split())
    return docs


def _unwrap_optional(tp: Any) -> tuple[Any, bool]:
    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        if len(args) == 1:
            return args[0], True
    return tp, False


def add_config_arguments(parser: argparse.ArgumentParser, cls: type) -> None:
    """Add one option per field of the dataclass `cls` to `parser`."""
    hints = typing.get_type_hints(cls)
    docs = field_docs(cls)
    for f in dataclasses.fields(cls):
        tp, optional = _unwrap_optional(hints[f.name])
        default = f.default if f.default is not dataclasses.MISSING else (
            f.default_factory() if f.default_factory is not dataclasses.MISSING else None)
        kwargs: dict[str, Any] = {"help": docs.get(f.name, "")}
        origin = typing.get_origin(tp)
        if tp is bool:
            kwargs["action"] = argparse.BooleanOptionalAction
        elif origin is typing.Literal:
            kwargs["choices"] = list(typing.get_args(tp))
            kwargs["type"] = type(kwargs["choices"][0])
        elif origin is tuple:
            kwargs["nargs"] = "+"
            kwargs["type"] = typing.get_args(tp)[0]
        else:
            kwargs["type"] = tp if tp in (int, float, str, Path) else str
        if f.metadata.get("positional"):
            if optional or default is not None:
                kwargs["nargs"] = "?"
                kwargs["default"] = default
            parser.add_argument(f.name, metavar=f.name.upper(), **kwargs)
            continue
        if default is not None:
            kwargs["help"] += f" (default: {_show(default)})"
        flag = "--" + f.name.replace("_", "-")
        required = default is None and not optional
        if f.metadata.get("repeat"):
            # Given values replace the default rather than extend it.
            kwargs["action"] = "append"
            kwargs.pop("nargs", None)
            default = None
        parser.add_argument(flag, dest=f.name, default=default, required=required, **kwargs)


def _show(value: Any) -> str:
    return " ".join(map(str, value)) if isinstance(value, tuple) else str(value)


def config_from_args(cls: type[T], namespace: argparse.Namespace) -> T:
    """Build the config dataclass from parsed arguments (lists become tuples)."""
    values = {}
    for f in dataclasses.fields(cls):
        value = getattr(namespace, f.name)
        if value is None and f.metadata.get("repeat"):
            continue  # not given: the field's default
        values[f.name] = tuple(value) if isinstance(value, list) else value
    return cls(**values)


def positional(**kwargs: Any) -> Any:
    """A dataclass field given as a positional command-line argument."""
    return dataclasses.field(metadata={"positional": True}, **kwargs)


def repeated(**kwargs: Any) -> Any:
    """A tuple field whose option may be given several times (`--scene a --scene b`)."""
    return dataclasses.field(metadata={"repeat": True}, **kwargs)
