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


def test_no_package_imports_another_packages_private_module():
    """A module whose name starts with ``_`` is its package's own: other packages import the public modules
    (``spiral_cad.core.inputs``, ``spiral_cad.core.kinds`` …), so a private module can change freely."""
    import ast
    from pathlib import Path

    root = Path(__file__).resolve().parents[2] / "spiral_cad"
    found = []
    for path in sorted(root.rglob("*.py")):
        package = path.relative_to(root).parts[0] if len(path.relative_to(root).parts) > 1 else ""
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module:
                if node.level == 0 and not node.module.startswith("spiral_cad."):
                    continue
                # the absolute module: relative imports resolved from the file's own package
                base = (
                    list(path.relative_to(root).parent.parts)[: len(path.relative_to(root).parent.parts) - (node.level - 1)]
                    if node.level
                    else []
                )
                parts = (base + node.module.split(".")) if node.level else node.module.split(".")[1:]
                if parts and parts[0] != package and any(p.startswith("_") and p != "__init__" for p in parts[1:]):
                    found.append(f"{path.relative_to(root)}: {'.' * node.level}{node.module}")
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    parts = alias.name.split(".")
                    if parts[0] == "spiral_cad" and len(parts) > 2 and parts[1] != package and any(p.startswith("_") for p in parts[2:]):
                        found.append(f"{path.relative_to(root)}: {alias.name}")
    assert not found, found
