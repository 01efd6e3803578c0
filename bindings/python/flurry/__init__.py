"""Flurry particle systems from Python.

Effects come from files, from the built-in library, or from Python: ``action``,
``domain``, ``emitter`` and ``group`` turn keyword arguments into the effect file's JSON
objects (snake_case keys become the format's camelCase), and ``effect`` hands the whole to
the C++ loader, which validates every field: errors are ``EffectError`` with the loader's
message and JSON path. Nothing here knows an action's fields; the loader is the one place
that does.

Attribute arrays (``Group.lane``) are numpy views of the group's storage, never copies.
"""
from __future__ import annotations

import json as _json
import re as _re
from typing import Any, Iterable

import numpy as _np

from ._flurry import (  # noqa: F401
    Context,
    Effect,
    EffectError,
    EffectInstance,
    Error,
    Group,
    GroupStats,
    InvalidArgument,
    IoError,
    RenderError,
    __version__,
    builtin_effects,
    cpu_instruction_set,
    load,
    has_render,
    has_vdb,
)
from . import _flurry

__all__ = [
    "Context", "Effect", "EffectError", "EffectInstance", "Error", "Group", "GroupStats", "InvalidArgument",
    "IoError", "RenderError", "action", "actions", "builtin_effects", "cpu_instruction_set",
    "domain", "domains",
    "effect", "emitter", "gather", "group", "load", "simulate",
]
if has_vdb:
    from ._flurry import write_vdb  # noqa: F401
    __all__.append("write_vdb")
if has_render:
    from ._flurry import Renderer  # noqa: F401
    __all__.append("Renderer")


def _camel(key: str) -> str:
    return _re.sub(r"_([a-z0-9])", lambda m: m.group(1).upper(), key)


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {_camel(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, _np.ndarray):
        return value.tolist()
    if isinstance(value, _np.generic):
        return value.item()
    return value


def action(type: str, **fields: Any) -> dict:
    """An action object: ``action("Gravity", acceleration=(0, -9.81, 0))``."""
    return {"type": type, **_jsonable(fields)}


def domain(type: str, **fields: Any) -> dict:
    """A domain object: ``domain("sphere", center=(0, 1, 0), outer_radius=0.5)``."""
    return {"type": type, **_jsonable(fields)}


class _Factory:
    """``actions.Gravity(acceleration=...)`` is ``action("Gravity", acceleration=...)``: any
    name is accepted here and checked by the loader when the effect is built."""

    def __init__(self, make, kind: str):
        self._make, self._kind = make, kind

    def __getattr__(self, name: str):
        if name.startswith("_"):
            raise AttributeError(name)

        def make(**fields: Any) -> dict:
            return self._make(name, **fields)

        make.__name__ = name
        make.__doc__ = f"The {self._kind} {name!r}; fields as in docs/effect-format.md."
        return make


actions = _Factory(action, "action")
domains = _Factory(domain, "domain")


def emitter(**fields: Any) -> dict:
    """An emitter object (``shape``, ``rate``, ``types``, ... as in the effect format)."""
    return _jsonable(fields)


def group(name: str, capacity: int, *, emitters: Iterable[dict] = (),
          actions: Iterable[dict] = (), **fields: Any) -> dict:
    """A group object of an effect."""
    return {"name": name, "capacity": capacity, "emitters": list(emitters),
            "actions": list(actions), **_jsonable(fields)}


def effect(groups: Iterable[dict], *, name: str = "python", **fields: Any) -> Effect:
    """Builds an effect from group objects; the C++ loader validates it (EffectError)."""
    doc = {"version": 1, "name": name, **_jsonable(fields), "groups": list(groups)}
    return Effect.parse(_json.dumps(doc), name=f"<{name}>")


def simulate(effect: Effect, *, backend: str = "cpu", threads: int = 0, seed: int | None = None,
             max_capacity: int = 0, device: str = "") -> Context:
    """A Context with the effect's seed (or `seed`) and dt, its groups built in it."""
    ctx = Context(seed=effect.seed if seed is None else seed, dt=effect.dt, threads=threads,
                  backend=backend, device=device)
    effect.build(ctx, max_capacity=max_capacity)
    return ctx


def gather(group: Group, attribute: str) -> _np.ndarray:
    """A COPY of an attribute as an (n, components) array (e.g. positions as (n, 3)); the
    group stores each component separately, so only Group.lane gives views."""
    comps = {"position": 3, "velocity": 3, "color": 4, "prevPosition": 3, "up": 3,
             "rotVelocity": 3, "positionB": 3, "velocityB": 3, "birthColor": 4}
    n = comps.get(attribute, 1)
    return _np.stack([group.lane(attribute, c) for c in range(n)], axis=1)
