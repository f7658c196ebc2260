"""Curated namespaces whose names load with their modules on first use (PEP 562)."""

from __future__ import annotations

from collections.abc import Callable
from importlib import import_module
from typing import Any

__all__ = ["lazy_names"]


def lazy_names(package: str, homes: dict[str, str], renamed: dict[str, str] | None = None
               ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:  # fmt: skip
    """A package's ``__getattr__`` and ``__dir__`` for the names of ``homes`` (name → its module, relative
    to ``package``): each is imported from its module when first asked for. An old name of ``renamed``
    (old → new) gives the new name's object with a ``DeprecationWarning`` (for one release); any other
    name is an AttributeError, as for a module."""
    renamed = renamed or {}

    def __getattr__(name: str) -> Any:
        if name in homes:
            return getattr(import_module(f".{homes[name]}", package), name)
        if name in renamed:
            import warnings

            new = renamed[name]
            warnings.warn(f"{package}.{name} is now {new}; the old name goes in the next release", DeprecationWarning, stacklevel=2)
            return __getattr__(new) if new in homes else getattr(import_module(package), new)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        return sorted(set(vars(import_module(package))) | set(homes))

    return __getattr__, __dir__
