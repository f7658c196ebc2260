"""Kernels compiled by numba when first needed, and the same kernels as plain Python meanwhile.

A kernel module declares its functions with ``jit`` / ``row_jit`` of its own
``Kernels(globals())`` (one per module: a function declared with another
module's ``Kernels`` is refused) and ends with ``seal()``. Each kernel's name
then holds a stand-in whose first call imports numba and compiles: every
kernel of every sealed module becomes a numba dispatcher at once, written
back into the module that declared it (so its own Python code and the other
kernels calling it find the dispatcher there), and each compiles, or is loaded
from numba's on-disk cache, at its first call. A module sealed after that
compiles at ``seal()``. Until then nothing imports numba, so
``import spiral_cad`` costs numpy alone.

``Kernels.python`` is the same source run by CPython: each function a copy
whose globals hold the other copies. The scalar API uses it while the kernels
are not compiled in this process (a first call answers in microseconds rather
than waiting seconds for a compiler), then compiles them once a process has
made ``SCALAR_CALLS_BEFORE_COMPILING`` scalar calls (before that, a kernel already compiled for
another call is used as it is). One source, one formula:
the two differ only in who executes it. Nothing else runs a kernel as plain
Python: an array call through a stand-in compiles first.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from types import FunctionType, SimpleNamespace
from typing import Any, TypeVar, cast

import numpy as np

__all__ = ["COMPILING", "Kernels", "REGISTRIES", "SCALAR_CALLS_BEFORE_COMPILING"]

#: A kernel function: the decorators return it unchanged, signature included.
F = TypeVar("F", bound=Callable[..., Any])

#: Scalar calls a process makes through the plain-Python kernels before it compiles them (a loop, not a REPL).
SCALAR_CALLS_BEFORE_COMPILING = 200

_LOCK = threading.RLock()

#: Every module's ``Kernels``, in import order: they compile together (a kernel may call another module's).
REGISTRIES: list[Kernels] = []

#: Whether this process has compiled its kernels (a module sealed later compiles at once).
_compiled_all = False


class Kernels:
    """The kernel functions of one module: plain Python until compiled.

    Args:
        namespace: the module's ``globals()``; every kernel declared here must be defined in that
            module, and its dispatcher is written back there.
    """

    def __init__(self, namespace: dict[str, Any]) -> None:
        self.namespace = namespace
        #: The module that declares these kernels and holds their dispatchers once compiled.
        self.module: str = namespace["__name__"]
        self.functions: dict[str, tuple[FunctionType, bool]] = {}
        self.compiled = False
        self.sealed = False
        self.scalar_calls = 0
        self._python: SimpleNamespace | None = None
        with _LOCK:
            REGISTRIES.append(self)

    def jit(self, function: F) -> F:
        """Declare a kernel (compiled on its own, called from other kernels)."""
        return self._declare(function, False)

    def row_jit(self, function: F) -> F:
        """Declare a kernel that is inlined into the kernels calling it (one solver row)."""
        return self._declare(function, True)

    def _declare(self, function: F, inline: bool) -> F:
        home = getattr(function, "__module__", None)
        if home != self.module:
            raise ValueError(f"kernel {function.__qualname__} of module {home} is declared with the Kernels of {self.module}; "
                             f"give {home} its own Kernels(globals()) so that its dispatcher is compiled into it")  # fmt: skip
        if self.sealed:
            raise ValueError(f"kernel {function.__qualname__} is declared after {self.module} was sealed")
        self.functions[function.__name__] = (cast(FunctionType, function), inline)
        return function

    def seal(self) -> None:
        """Put a stand-in under each kernel's name: its first call compiles every module's kernels."""
        with _LOCK:
            self.sealed = True
            for name in self.functions:
                self.namespace[name] = _Uncompiled(self, name)
            if _compiled_all:
                self.compile()

    def compile(self) -> None:
        """Make every kernel of every sealed module a numba dispatcher, in the module that declared it,
        cached on disk where a cache can be written.

        Numba refuses to decorate a cached function when it finds no writable
        cache location (a read-only install without a writable home): the
        kernels then compile in memory at first use.
        """
        global _compiled_all
        with _LOCK:
            if self.compiled:
                return
            from numba import njit

            _announce_compiling()
            for registry in REGISTRIES:
                if registry.sealed and not registry.compiled:
                    registry._make_dispatchers(njit)
            for registry in REGISTRIES:  # a kernel another module imported by name: its dispatcher there too
                for name, value in list(registry.namespace.items()):
                    if isinstance(value, _Uncompiled) and value._kernels.compiled:
                        registry.namespace[name] = value._kernels.namespace[value.__name__]
            _compiled_all = True

    def _make_dispatchers(self, njit: Callable[..., Any]) -> None:
        for name, (function, inline) in self.functions.items():
            options: dict[str, Any] = dict(nogil=True, error_model="numpy", inline="always" if inline else "never")
            try:
                self.namespace[name] = njit(cache=True, **options)(function)
            except RuntimeError:
                self.namespace[name] = njit(cache=False, **options)(function)
        self.compiled = True

    @property
    def python(self) -> SimpleNamespace:
        """The kernels as plain Python functions calling each other (nothing compiled); a kernel another
        module declared, imported here by name, is that module's plain-Python copy."""
        if self._python is None:
            with _LOCK:
                _python_copies()
        assert self._python is not None, f"{self.module} is not sealed"
        return self._python

    def guarded(self) -> Any:
        """The plain-Python kernels with the kernels' float model, not counted as scalar calls
        (for a message's numbers: never compiles unless a kernel raises)."""
        return _Python(self)

    def for_scalar_call(self) -> Any:
        """The kernels a scalar call should use: a kernel this process has compiled code for (or loaded
        from numba's cache) as it is, any other as plain Python.

        A process that keeps making scalar calls compiles them after
        ``SCALAR_CALLS_BEFORE_COMPILING`` calls (once; numba's cache makes
        that cheap in the next process). Until then a scalar call never waits for a compiler, even
        after another kernel was compiled for an array call (a solver row takes seconds to compile).
        """
        if self.scalar_calls < SCALAR_CALLS_BEFORE_COMPILING:
            self.scalar_calls += 1
            return _Python(self) if not self.compiled else _Ready(self)
        self.compile()
        return _Compiled(self.namespace)


#: The line a person at a terminal reads while the first kernels compile (measured: ``benchmarks/bench_cold.py``).
COMPILING = ("spiral_cad: compiling the curve kernels for this machine (first run only; numba caches them): "
             "about 3 s for a first curve or fillet, 15 s for the batch solvers")  # fmt: skip
_announcing = False


def _python_copies() -> None:
    """Give every sealed registry without them its plain-Python copies: each kernel a function whose globals
    are a copy of its module's, where a kernel of any registry imported by name (its stand-in, dispatcher or
    function) is that kernel's plain-Python copy."""
    owners: dict[int, tuple[Kernels, str]] = {}
    for registry in REGISTRIES:
        for name, (function, _) in registry.functions.items():
            owners[id(function)] = registry, name
    scopes = []
    for registry in REGISTRIES:
        if registry._python is None and registry.sealed:
            scope = {k: v for k, v in registry.namespace.items() if k not in registry.functions}
            scope["math"] = _FLOAT_MATH
            for name, (function, _) in registry.functions.items():
                scope[name] = FunctionType(function.__code__, scope, name, function.__defaults__, function.__closure__)
            registry._python = SimpleNamespace(**{name: scope[name] for name in registry.functions})
            scopes.append(scope)
    for scope in scopes:
        for name, value in list(scope.items()):
            owner = (value._kernels, value.__name__) if isinstance(value, _Uncompiled) else owners.get(id(getattr(value, "py_func", value)))
            if owner is not None and owner[0]._python is not None:
                scope[name] = getattr(owner[0]._python, owner[1])


def _announce_compiling() -> None:
    """Print ``COMPILING`` once, on a terminal's stderr, when numba first compiles one of our kernels (a
    kernel loaded from numba's cache compiles nothing and says nothing; a pipe or a test hears nothing)."""
    global _announcing
    if _announcing:
        return
    _announcing = True
    import sys

    from numba.core import event

    class Announce(event.Listener):
        said = False

        def on_start(self, found: Any) -> None:
            dispatcher = found.data.get("dispatcher") if isinstance(found.data, dict) else None
            module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
            if not self.said and module.startswith("spiral_cad.") and sys.stderr.isatty():
                self.said = True
                print(COMPILING, file=sys.stderr, flush=True)

        def on_end(self, found: Any) -> None:
            return None

    event.register("numba:compile", Announce())  # type: ignore[no-untyped-call]


def _float_semantics(name: str) -> Callable[..., Any]:
    """``math.name`` with the kernels' floating-point model: a domain error gives NaN, an overflow
    what numpy's function of that name gives (±inf), and the result is a numpy float, so that a
    later division by zero gives inf rather than raising."""
    function = getattr(math, name)
    fallback = getattr(np, name, None)

    def kernel_math(*args: Any) -> Any:
        try:
            return np.float64(function(*args))
        except ValueError:
            return np.float64(math.nan)
        except OverflowError:
            if fallback is None:
                raise
            return np.float64(fallback(*args))

    return kernel_math


#: ``math`` as the plain-Python kernels see it (numba's math functions follow numpy's float model).
_FLOAT_MATH = SimpleNamespace(
    **{
        **{name: getattr(math, name) for name in dir(math) if not name.startswith("_")},
        **{
            name: _float_semantics(name)
            for name in (
                "sqrt",
                "log",
                "log2",
                "log10",
                "log1p",
                "acos",
                "asin",
                "atan2",
                "exp",
                "expm1",
                "ldexp",
                "pow",
                "cosh",
                "sinh",
                "hypot",
                "fmod",
                "atanh",
                "acosh",
            )
        },
    }
)


def _plain(value: Any) -> Any:
    """Numpy scalars as the Python numbers a compiled kernel returns (tuples element by element)."""
    if isinstance(value, tuple):
        return tuple(_plain(v) for v in value)
    if isinstance(value, np.floating):
        return float(value)
    if isinstance(value, np.integer):
        return int(value)
    return value


class _Python:
    """The plain-Python kernels, called with numpy floats (whose division by zero gives inf, as in
    the kernels, rather than raising); a kernel that still raises runs compiled instead."""

    __slots__ = ("_kernels",)

    def __init__(self, kernels: Kernels) -> None:
        self._kernels = kernels

    def __getattr__(self, name: str) -> Callable[..., Any]:
        kernels = self._kernels
        function: Callable[..., Any] = getattr(kernels.python, name)

        def guarded(*args: Any) -> Any:
            floats = tuple(np.float64(a) if type(a) is float else a for a in args)
            try:
                with np.errstate(all="ignore"):
                    return _plain(function(*floats))
            except (ArithmeticError, ValueError):
                kernels.compile()
                return kernels.namespace[name](*args)

        return guarded


class _Uncompiled:
    """A kernel's name before its process compiles: calling it compiles every kernel, then calls the
    dispatcher (which from then on is what the name holds)."""

    def __init__(self, kernels: Kernels, name: str) -> None:
        function = kernels.functions[name][0]
        self._kernels = kernels
        self.__name__ = name
        self.__doc__ = function.__doc__
        self.__wrapped__ = function

    def __call__(self, *args: Any) -> Any:
        self._kernels.compile()
        return self._kernels.namespace[self.__name__](*args)

    def __repr__(self) -> str:
        return f"<kernel {self._kernels.module}.{self.__name__}, not compiled yet>"


class _Ready(_Python):
    """The kernels that hold compiled code, and the plain-Python copy of any other."""

    __slots__ = ()

    def __getattr__(self, name: str) -> Callable[..., Any]:
        dispatcher = self._kernels.namespace[name]
        if getattr(dispatcher, "signatures", None):
            found: Callable[..., Any] = dispatcher
            return found
        return super().__getattr__(name)


class _Compiled:
    """Attribute access to a compiled module's kernels (its namespace, read directly)."""

    __slots__ = ("_namespace",)

    def __init__(self, namespace: dict[str, Any]) -> None:
        self._namespace = namespace

    def __getattr__(self, name: str) -> Callable[..., Any]:
        function: Callable[..., Any] = self._namespace[name]
        return function
