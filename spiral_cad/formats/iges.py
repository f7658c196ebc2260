"""IGES through OCCT's writer in BRep mode: true lines and circles, each spiral as an exact entity 126.

The file declares its unit (global section unit flag and name: 2 MM, 10 CM,
6 M, 7 KM, 1 INCH, 4 FT) and carries the coordinates unscaled: OCCT's writer
is told that the session unit is the file unit. The design name is the
sender's product id and the file name; the originating system is
``spiral_cad <version>``; author and organisation are left empty.
"""

from __future__ import annotations

import os
from typing import Any

from OCP.IGESControl import IGESControl_Controller, IGESControl_Writer
from OCP.IGESData import IGESData_IGESWriter
from OCP.IGESSelect import IGESSelect_WorkLibrary
from OCP.Interface import Interface_Static
from OCP.TCollection import TCollection_HAsciiString

from ..cad.occ import as_occ_shape, captured_messages, print_model
from ..core.units import MM_PER_UNIT

#: IGES unit names as OCCT's writer takes them.
_IGES_UNIT = {"mm": "MM", "cm": "CM", "m": "M", "km": "KM", "in": "IN", "ft": "FT"}


def write_iges(obj: Any, path: str | os.PathLike, name: str, units: str, originating_system: str) -> None:
    """Write ``obj`` (chains or a shape, see ``as_occ_shape``) as IGES in BRep mode.

    Reals are printed with 17 significant digits (OCCT prints 9 decimals by
    default): coordinates survive the round trip; a circle's radius is
    stored only as the distance from its centre to its start point, so it
    reads back within 2 ulp.

    Raises:
        OSError: the writer failed.
    """
    IGESControl_Controller.Init_s()
    Interface_Static.SetIVal_s("write.iges.brep.mode", 1)
    Interface_Static.SetIVal_s("write.convertsurface.mode", 0)
    writer = IGESControl_Writer(_IGES_UNIT[units], 1)
    model = writer.Model()
    header = model.GlobalSection()
    header.SetCascadeUnit(MM_PER_UNIT[units])  # the shape is already in the file unit: no rescaling
    header.SetSendName(TCollection_HAsciiString(name))
    header.SetFileName(TCollection_HAsciiString(os.path.basename(os.fspath(path))))
    header.SetSystemId(TCollection_HAsciiString(originating_system))
    header.SetInterfaceVersion(TCollection_HAsciiString(originating_system))
    header.SetReceiveName(TCollection_HAsciiString(name))
    header.SetAuthorName(TCollection_HAsciiString(""))
    header.SetCompanyName(TCollection_HAsciiString(""))
    model.SetGlobalSection(header)
    with captured_messages():
        if not writer.AddShape(as_occ_shape(obj)):
            raise OSError(f"IGES transfer failed for {name!r}")
        writer.ComputeModel()
    print_model(IGESData_IGESWriter(model), IGESSelect_WorkLibrary.DefineProtocol_s(), path, "IGES")
