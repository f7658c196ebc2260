"""IGES through OCCT's writer in BRep mode: true lines and circles, each spiral as an exact entity 126.

The file declares its unit (global section unit flag and name: 2 MM, 10 CM,
6 M, 7 KM, 1 INCH, 4 FT) and carries the coordinates unscaled: OCCT's writer
is told that the session unit is the file unit. The design name is the
sender's product id and, with the file name, in the global section; the
originating system is ``spiral_cad <version>``; author and organisation are
left empty. The top entity (the composite curve of a chain, the group of a
list of chains) carries the name as its entity label (8 characters) and as
a name property (entity 406 form 15), which OCCT-based importers such as
FreeCAD show; the curves of a group are named ``NAME-k``. IGES text is
7-bit ASCII: names pass through ``spiral_cad.io.names.iges_text`` (and
the file name is cut to 255 characters).
"""

from __future__ import annotations

import os
from typing import Any

from OCP.IGESBasic import IGESBasic_Group, IGESBasic_Name
from OCP.IGESControl import IGESControl_Controller, IGESControl_Writer
from OCP.IGESData import IGESData_IGESWriter
from OCP.IGESSelect import IGESSelect_WorkLibrary
from OCP.Interface import Interface_Static
from OCP.TCollection import TCollection_HAsciiString

from ..core.units import MM_PER_UNIT
from ..io.names import MAX_NAME_LENGTH, iges_text
from .console import captured_messages
from .occ import as_occ_shape, print_model

#: IGES unit names as OCCT's writer takes them.
_IGES_UNIT = {"mm": "MM", "cm": "CM", "m": "M", "km": "KM", "in": "IN", "ft": "FT"}


def _text(text: str) -> TCollection_HAsciiString:
    return TCollection_HAsciiString(iges_text(text))


def _global_text(text: str) -> TCollection_HAsciiString:
    """A global-section string, given in Hollerith form: OCCT's writer takes any string that starts like one
    (``12Habc``, a name ``0H0``) as already written so and keeps only what follows the H."""
    ascii_text = iges_text(text)
    return TCollection_HAsciiString(f"{len(ascii_text)}H{ascii_text}")


def _name_entity(writer: IGESControl_Writer, entity: Any, name: str) -> None:
    """Give ``entity`` the label and the name property ``name`` (as OCCT's XDE writer does)."""
    entity.SetLabel(_text(name[:8]), -1)
    prop = IGESBasic_Name()
    prop.Init(1, _text(name))
    entity.AddProperty(prop)
    writer.AddEntity(prop)


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
    header.SetSendName(_global_text(name))
    # OCCT's writer overruns a buffer on strings of ~1300 characters: the file name is capped like a name
    header.SetFileName(_global_text(os.path.basename(os.fspath(path))[:MAX_NAME_LENGTH]))
    header.SetSystemId(_global_text(originating_system))
    header.SetInterfaceVersion(_global_text(originating_system))
    header.SetReceiveName(_global_text(name))
    header.SetAuthorName(TCollection_HAsciiString(""))
    header.SetCompanyName(TCollection_HAsciiString(""))
    model.SetGlobalSection(header)
    shape = as_occ_shape(obj)
    with captured_messages():
        first = model.NbEntities() + 1
        if not writer.AddShape(shape) or model.NbEntities() < first:
            raise OSError(f"IGES transfer failed for {name!r}")
        top = model.Entity(first)  # the transfer adds the shape's entity, then what it references
        _name_entity(writer, top, name)
        if isinstance(top, IGESBasic_Group):
            for k in range(1, top.NbEntities() + 1):
                _name_entity(writer, top.Entity(k), f"{name}-{k}")
        writer.ComputeModel()
    print_model(IGESData_IGESWriter(model), IGESSelect_WorkLibrary.DefineProtocol_s(), path, "IGES")
