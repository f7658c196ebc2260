"""The numeric core stays free of the CAD kernel."""

import subprocess
import sys

CAD_MODULES = ("OCP", "build123d", "cadquery")


def test_core_imports_without_the_cad_kernel():
    code = (
        "import sys, spiral_cad, spiral_cad.core.batch, spiral_cad.core, spiral_cad.core.nurbs\n"
        "import importlib.util\n"
        "for extra in ('spiral_cad.design', 'spiral_cad.app.plots'):\n"
        "    if importlib.util.find_spec(extra): importlib.import_module(extra)\n"
        f"bad = [m for m in sys.modules if m.split('.')[0] in {CAD_MODULES!r}]\n"
        "print(bad); sys.exit(1 if bad else 0)\n"
    )
    code = "import importlib\n" + code
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
