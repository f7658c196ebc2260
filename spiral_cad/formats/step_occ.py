"""STEP for shapes that are not chains (solids, faces, wires from build123d/CadQuery/OCP), through OCCT's writer.

The shape's numbers are taken to be in the given unit and written unscaled
with that unit declared (``write.step.unit`` with the model's local length
unit set to match); the product is named after the design and the header's
originating system is ``spiral_cad <version>``, with empty author and
organisation. Reals are printed with 17 significant digits.
"""

from __future__ import annotations

import os
from typing import Any

from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.Interface import Interface_Static
from OCP.StepAP214 import StepAP214
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.StepData import StepData_StepWriter
from OCP.TCollection import TCollection_HAsciiString

from ..cad.occ import as_occ_shape, captured_messages, print_model
from ..core.units import MM_PER_UNIT

#: OCCT's names for ``write.step.unit``.
_STEP_UNIT = {"mm": "MM", "cm": "CM", "m": "M", "km": "KM", "in": "INCH", "ft": "FT"}


def write_shape_step(obj: Any, path: str | os.PathLike, name: str, units: str, originating_system: str) -> None:
    """Write any OCP/build123d/CadQuery shape as STEP AP214 in ``units``.

    Raises:
        ValueError: ``obj`` is not a shape.
        OSError: the transfer or the printing failed.
    """
    shape = as_occ_shape(obj)
    writer = STEPControl_Writer()
    Interface_Static.SetCVal_s("write.step.unit", _STEP_UNIT[units])
    Interface_Static.SetCVal_s("write.step.product.name", name)
    writer.Model().SetLocalLengthUnit(MM_PER_UNIT[units])  # the shape is in the file unit: no rescaling
    with captured_messages():
        status = writer.Transfer(shape, STEPControl_AsIs)
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise OSError(f"STEP transfer failed for {name!r}")
    header = APIHeaderSection_MakeHeader(writer.Model())
    header.SetName(TCollection_HAsciiString(name))
    header.SetOriginatingSystem(TCollection_HAsciiString(originating_system))
    header.SetPreprocessorVersion(TCollection_HAsciiString(originating_system))
    header.SetAuthorValue(1, TCollection_HAsciiString(""))
    header.SetOrganizationValue(1, TCollection_HAsciiString(""))
    header.SetAuthorisation(TCollection_HAsciiString(""))
    print_model(StepData_StepWriter(writer.Model()), StepAP214.Protocol_s(), path, "STEP")
