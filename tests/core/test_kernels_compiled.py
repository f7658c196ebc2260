"""Kernels are compiled where they are declared: no kernel may run as plain Python by accident.

Every module that declares numba kernels has its own ``Kernels`` (``spiral_cad.core.jit``); once a
process compiles, each kernel's name in the module that declared it holds a numba dispatcher, so
that module's own Python code and every kernel calling it run compiled code. The plain-Python copies
(``Kernels.python``) serve the scalar API alone: a kernel without compiled code in its process, until
the process has made its budget of scalar calls.

Each check runs in a fresh interpreter: what is compiled is a property of a process.
"""

import ast
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "spiral_cad"

#: Imports every module below the CAD layer (the only ones that may hold kernels) and lists the registries.
PRELUDE = """
import importlib, pkgutil, sys
import spiral_cad
from spiral_cad.core import jit as kernels_jit
for package in ("core", "design", "continuity", "io"):
    root = importlib.import_module(f"spiral_cad.{package}")
    for info in pkgutil.walk_packages(root.__path__, root.__name__ + "."):
        importlib.import_module(info.name)
registries = {r.module: r for r in kernels_jit.REGISTRIES}
"""


def run(code: str) -> str:
    done = subprocess.run([sys.executable, "-c", PRELUDE + textwrap.dedent(code)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return done.stdout


def declared_kernels() -> dict[str, set[str]]:
    """Module → names of the functions its source decorates with a ``jit`` or ``row_jit`` (any spelling)."""
    found: dict[str, set[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        module = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef):
                names = [ast.unparse(d) for d in node.decorator_list]
                if any(n.split(".")[-1] in ("jit", "row_jit", "njit") for n in names):
                    found.setdefault(module, set()).add(node.name)
    return found


def test_every_decorated_kernel_is_registered_in_its_own_module():
    """A kernel decorated anywhere is declared with its own module's ``Kernels`` (the slip that left
    ``core/space.py`` and ``design/rounding.py`` running plain Python cannot come back unseen)."""
    declared = declared_kernels()
    assert {"spiral_cad.core._kernels", "spiral_cad.core.space", "spiral_cad.design.rounding"} <= set(declared)
    registered = eval(run("print({m: sorted(r.functions) for m, r in registries.items()})"))
    assert {m: set(names) for m, names in registered.items()} == declared


def test_declaring_a_kernel_with_another_modules_registry_is_refused():
    from spiral_cad.core import _kernels as K

    def stray(x: float) -> float:
        return x

    stray.__module__ = "somewhere.else"
    with pytest.raises(ValueError, match=r"stray of module somewhere.else .* give somewhere.else its own Kernels"):
        K.KERNELS.jit(stray)


def test_after_compiling_every_kernel_in_every_module_is_a_dispatcher_and_nothing_else_is_plain_python():
    out = run("""
        import numpy as np
        from spiral_cad import line_to_circle
        from spiral_cad.design import round_corners_batch

        # Before: numba is not even imported; every kernel name holds a stand-in, never a plain function.
        assert "numba" not in sys.modules
        for module, registry in registries.items():
            for name in registry.functions:
                held = vars(sys.modules[module])[name]
                assert type(held).__name__ == "_Uncompiled", (module, name, held)
        # The scalar API runs plain Python while the process has not compiled.
        line_to_circle((0, 0), (1, 0), (10, 5), 3)
        assert "numba" not in sys.modules and not any(r.compiled for r in registries.values())

        # Anything else that needs a kernel compiles first: here a batch call that reaches kernels of
        # core/_kernels, core/space and design/rounding, with plain Python forbidden.
        type(next(iter(registries.values()))).python = property(lambda self: (_ for _ in ()).throw(AssertionError("plain Python")))
        rng = np.random.default_rng(3)
        points = np.cumsum(rng.uniform(-1, 1, (50, 3)), axis=0)
        batch = round_corners_batch(points[:-2], points[1:-1], points[2:])
        assert batch.ok.sum() > 40

        from numba.core.registry import CPUDispatcher

        for module, registry in registries.items():
            assert registry.compiled, module
            namespace = vars(sys.modules[module])
            for name in registry.functions:
                assert isinstance(namespace[name], CPUDispatcher), (module, name, namespace[name])
        # No stand-in is left anywhere a module could have copied one.
        for module in list(sys.modules.values()):
            if getattr(module, "__name__", "").startswith("spiral_cad"):
                stale = [n for n, v in vars(module).items() if type(v).__name__ == "_Uncompiled"]
                assert not stale, (module.__name__, stale)
        # The kernels the batch used were compiled (not merely wrapped).
        from spiral_cad.core import space
        from spiral_cad.design import rounding
        assert space._pair_residuals.signatures and space._place_rows.signatures and rounding._pair_joints.signatures
        print(len(registries), sum(len(r.functions) for r in registries.values()))
    """)
    modules, kernels = map(int, out.split())
    assert modules >= 4 and kernels > 100


def test_the_scalar_api_compiles_after_its_budget_of_plain_python_calls():
    run("""
        from numba.core.registry import CPUDispatcher
        from spiral_cad import line_to_circle
        from spiral_cad.core import _kernel_line_circle as KLC
        from spiral_cad.core.jit import SCALAR_CALLS_BEFORE_COMPILING

        for _ in range(SCALAR_CALLS_BEFORE_COMPILING):
            line_to_circle((0, 0), (1, 0), (10, 5), 3)
        assert not KLC.KERNELS.compiled
        line_to_circle((0, 0), (1, 0), (10, 5), 3)
        assert all(r.compiled for r in registries.values())
        assert isinstance(KLC.line_to_circle_row, CPUDispatcher)
    """)


def test_a_scalar_call_after_an_array_call_runs_plain_python_rather_than_wait_for_its_kernel():
    """A batch call compiles the kernels it reaches; a scalar call after it uses those, and the plain-Python
    copy of a solver row nothing has compiled (seconds of compiling saved: the first g2_fillet's case)."""
    run("""
        import numpy as np
        from spiral_cad import line_to_circle
        from spiral_cad.core import _kernel_line_circle as KLC
        from spiral_cad.core import _kernels as K
        from spiral_cad.design import round_corners_batch

        rng = np.random.default_rng(3)
        points = np.cumsum(rng.uniform(-1, 1, (50, 3)), axis=0)
        round_corners_batch(points[:-2], points[1:-1], points[2:])
        assert K.KERNELS.compiled and not KLC.line_to_circle_row.signatures
        plain = line_to_circle((0, 0), (1, 0), (10, 5), 3)
        assert not KLC.line_to_circle_row.signatures
        from spiral_cad.core.jit import SCALAR_CALLS_BEFORE_COMPILING
        for _ in range(SCALAR_CALLS_BEFORE_COMPILING):
            compiled = line_to_circle((0, 0), (1, 0), (10, 5), 3)
        assert KLC.line_to_circle_row.signatures
        a, b = plain.spirals[0].control_points, compiled.spirals[0].control_points
        assert np.abs(np.asarray(a) - np.asarray(b)).max() <= 1e-12 * 10
    """)


def test_a_person_at_a_terminal_is_told_once_that_the_kernels_compile_and_a_pipe_is_not(tmp_path):
    """With numba's cache empty, a first curve prints ``COMPILING`` once on a terminal's stderr; on a pipe,
    or with the cache filled, nothing."""
    import os
    import pty

    from spiral_cad.core.jit import COMPILING

    code = ("import spiral_cad as sc, numpy as np; sc.batch.line_to_circle(np.zeros((3, 2)), np.tile([1.0, 0.0], (3, 1)), "
            "np.tile([10.0, 5.0], (3, 1)), np.full(3, 3.0))")  # fmt: skip
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}

    def on_terminal() -> str:
        leader, follower = pty.openpty()
        done = subprocess.run([sys.executable, "-c", code], stderr=follower, stdout=subprocess.DEVNULL, env=env, timeout=600)
        os.close(follower)
        said = b""
        while True:
            try:
                chunk = os.read(leader, 4096)
            except OSError:
                break
            if not chunk:
                break
            said += chunk
        os.close(leader)
        assert done.returncode == 0, said
        return said.decode()

    first = on_terminal()
    assert first.count(COMPILING) == 1, first
    assert COMPILING not in on_terminal()  # the cache is filled now
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "other")
    piped = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600)
    assert piped.returncode == 0 and COMPILING not in piped.stderr
