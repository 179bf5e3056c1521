"""A constructor argument that names a registered class or is an instance of it: the env's
``reward=`` (reward modes) and ``observation=`` (observation views)."""

from __future__ import annotations

from typing import TypeVar

__all__ = ["choose"]

T = TypeVar("T")


def choose(field: str, kind: str, value: object, registry: dict[str, type[T]], base: type[T]) -> T:
    """``value`` when it is a ``base`` instance, else a new instance of the class it names;
    anything else is a ValueError naming ``field`` and the choices."""
    if isinstance(value, base):
        return value
    if not isinstance(value, str) or value not in registry:
        raise ValueError(
            f"{field}: unknown {kind} {value!r}; expected one of {list(registry)} or a "
            f"{base.__module__}.{base.__name__} instance"
        )
    return registry[value]()
