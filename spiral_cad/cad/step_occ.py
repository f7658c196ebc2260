"""STEP for shapes that are not chains (solids, faces, wires from build123d/CadQuery/OCP), through OCCT's writer.

The shape's numbers are taken to be in the given unit and written unscaled
with that unit declared (``write.step.unit`` with the model's local length
unit set to match); the product is named after the design and the header's
originating system is ``spiral_cad <version>``, with empty author and
organisation. Reals are printed with 17 significant digits.

OCCT's writer would print a name's non-ASCII characters as raw UTF-8 and a
quote before ``)`` in a form its own reader cannot parse, so it is given a
random ASCII placeholder that is then replaced by the name encoded as
ISO 10303-21 requires (``spiral_cad.io.names.step_string``); the
product is named exactly ``name`` (OCCT would append a counter).
"""

from __future__ import annotations

import os
import re
import secrets
from pathlib import Path
from typing import Any

from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.Interface import Interface_Static
from OCP.StepAP214 import StepAP214
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.StepData import StepData_StepWriter
from OCP.TCollection import TCollection_HAsciiString

from .occ import as_occ_shape, print_model
from .console import captured_messages
from ..core.units import MM_PER_UNIT
from ..io.names import step_string

#: OCCT's names for ``write.step.unit``.
_STEP_UNIT = {"mm": "MM", "cm": "CM", "m": "M", "km": "KM", "in": "INCH", "ft": "FT"}


def write_shape_step(
    obj: Any, path: str | os.PathLike, name: str, units: str, originating_system: str, description: str | None = None
) -> None:
    """Write any OCP/build123d/CadQuery shape as STEP AP214 in ``units`` (``description``: the
    header's FILE_DESCRIPTION, printable ASCII without quotes or backslashes).

    Raises:
        ValueError: ``obj`` is not a shape.
        OSError: the transfer or the printing failed.
    """
    shape = as_occ_shape(obj)
    if description is not None and not (description.isascii() and description.isprintable() and not set("'\\") & set(description)):
        raise ValueError(f"a STEP description must be printable ASCII without quotes or backslashes; got {description!r:.80}")
    placeholder = f"SPIRALCADNAME{secrets.token_hex(12).upper()}"
    writer = STEPControl_Writer()
    Interface_Static.SetCVal_s("write.step.unit", _STEP_UNIT[units])
    Interface_Static.SetCVal_s("write.step.product.name", placeholder)
    writer.Model().SetLocalLengthUnit(MM_PER_UNIT[units])  # the shape is in the file unit: no rescaling
    with captured_messages():
        status = writer.Transfer(shape, STEPControl_AsIs)
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise OSError(f"STEP transfer failed for {name!r}")
    header = APIHeaderSection_MakeHeader(writer.Model())
    header.SetName(TCollection_HAsciiString(placeholder))
    header.SetOriginatingSystem(TCollection_HAsciiString(originating_system))
    header.SetPreprocessorVersion(TCollection_HAsciiString(originating_system))
    header.SetAuthorValue(1, TCollection_HAsciiString(""))
    header.SetOrganizationValue(1, TCollection_HAsciiString(""))
    header.SetAuthorisation(TCollection_HAsciiString(""))
    if description is not None:
        header.SetDescriptionValue(1, TCollection_HAsciiString(description))
    print_model(StepData_StepWriter(writer.Model()), StepAP214.Protocol_s(), path, "STEP")
    text = Path(path).read_bytes()
    # OCCT appends a per-session counter to the product name ("NAME 1", "NAME 2", …): drop it
    encoded = step_string(name)[1:-1].encode("ascii")
    text, count = re.subn(re.escape(placeholder.encode()) + rb"( \d+)?", lambda _: encoded, text)
    if count < 2:  # the product and the header
        raise OSError(f"the STEP writer did not write the product name for {name!r}")
    Path(path).write_bytes(text)
