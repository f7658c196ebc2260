"""The face checker on parts other CAD systems wrote (issue 39): edge by edge against the independent
measure (``face_independent``) and, where installed, FreeCAD's reading of the same file."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

pytest.importorskip("OCP")

from face_calibration import compare_file, originating_system  # noqa: E402
from helpers import freecad_lib  # noqa: E402

PARTS = sorted((Path(__file__).parent.parent / "data" / "parts").glob("*.st*p"))
FREECAD = freecad_lib()
#: FreeCAD (system Python): how many faces the file holds and how many edges two faces share
FREECAD_COUNTS = (
    "import json, sys; sys.path.append(sys.argv[1]); import FreeCAD, Part; s = Part.read(sys.argv[2]); "
    "print(json.dumps([len(s.Faces), s.isValid(), "
    "sum(len(s.ancestorsOfType(e, Part.Face)) == 2 for e in s.Edges)]))"
)


def test_the_committed_parts_are_there():
    assert PARTS, "tests/data/parts holds no STEP file"


@pytest.mark.parametrize("path", PARTS, ids=[p.name for p in PARTS])
def test_the_checker_agrees_with_the_independent_measure_on_every_shared_edge(path):
    found = compare_file(path)
    assert found["edges"] > 0 and found["only_checker"] == found["only_measure"] == 0
    assert found["false_pass"] == [] and found["false_fail"] == [] and found["unmeasurable"] == []
    assert found["agree"] == found["edges"]


@pytest.mark.skipif(FREECAD is None, reason="FreeCAD is not installed (Debian/Ubuntu: apt-get install freecad-python3)")
@pytest.mark.parametrize("path", PARTS, ids=[p.name for p in PARTS])
def test_freecad_reads_the_faces_and_shared_edges_the_checker_judges(path):
    run = subprocess.run(["/usr/bin/python3", "-c", FREECAD_COUNTS, FREECAD, str(path)], capture_output=True,
                         text=True, timeout=120)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    faces, valid, shared = json.loads(run.stdout.splitlines()[-1])
    found = compare_file(path)
    assert valid and (faces, shared) == (found["faces"], found["edges"])


def test_the_cad_system_is_read_from_the_header(tmp_path):
    step = tmp_path / "a.step"
    step.write_text(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\nFILE_NAME(/* name */ 'a.stp',/* time_stamp */ "
        "'2020-11-25T12:55:58',('PR'),(''),/* preprocessor_version */ 'ST-DEVELOPER v18.1',\n"
        "/* originating_system */ 'Autodesk Inventor 2021',/* authorisation */ '');\nENDSEC;\n"
    )
    assert originating_system(step) == "Autodesk Inventor 2021"
    iges = tmp_path / "a.igs"
    globals_ = "1H,,1H;,7HSURF114,11HSURF114.IGS,26HRhinoceros ( Feb 28 2010 ),3HXYZ,32,8;"
    lines = ["S" + " " * 71 + "S      1"] + [f"{globals_[i : i + 72]:<72}G{n + 1:7d}" for n, i in enumerate(range(0, len(globals_), 72))]
    iges.write_text("\n".join(lines) + "\n")
    assert originating_system(iges) == "Rhinoceros ( Feb 28 2010 )"
