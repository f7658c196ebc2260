"""One policy for the names and texts we write into files, and how each format carries them.

A *name* (the ``name`` of every writer: STEP product, IGES product and entity
name, DXF layer, SVG id and title, OpenDRIVE header and road names) is a
string of 1 to ``MAX_NAME_LENGTH`` (255) characters, not all spaces, of any
Unicode text except control characters (C0, DEL, C1), line and paragraph
separators, lone surrogates and noncharacters (U+FFFE, U+FFFF, …). A *text*
(the OpenDRIVE ``geo_reference``) follows the same rule with a cap of
``MAX_TEXT_LENGTH`` (10 000) characters and may also hold newlines and tabs
(multi-line WKT). Anything else is a ``ValueError`` naming the argument.

What each format must escape, done by the functions below:

* STEP (ISO 10303-21): ``'`` doubled, ``\\`` doubled, other characters
  outside printable ASCII as ``\\X2\\…\\X0\\`` (BMP) or ``\\X4\\…\\X0\\``
  (``step_string``);
* IGES: 7-bit ASCII only; accents are dropped (é → e) and any other
  character becomes ``?`` (``iges_text``); OCCT's writer counts the
  Hollerith lengths;
* DXF: layer names may not hold ``< > / \\ " : ; ? * | =`` or a backquote;
  each becomes ``_`` (``dxf_layer_name``);
* XML (SVG, OpenDRIVE): entities are escaped by the XML writers; an SVG
  ``id`` keeps only XML name characters (``xml_id``).
"""

from __future__ import annotations

import re
import unicodedata
from itertools import groupby
from typing import Any

MAX_NAME_LENGTH = 255
MAX_TEXT_LENGTH = 10_000

#: Unicode categories no file of ours can carry: controls, surrogates, line and paragraph separators.
_REFUSED_CATEGORIES = {"Cc", "Cs", "Zl", "Zp"}


def _refused(character: str, multiline: bool) -> bool:
    code = ord(character)
    if multiline and character in "\n\t":
        return False
    noncharacter = 0xFDD0 <= code <= 0xFDEF or (code & 0xFFFE) == 0xFFFE
    return noncharacter or unicodedata.category(character) in _REFUSED_CATEGORIES


def check_name(value: Any, argument: str = "name", *, limit: int = MAX_NAME_LENGTH, multiline: bool = False) -> str:
    """``value`` if it is a name (or, with ``multiline``, a text) every writer can carry.

    Args:
        value: the name.
        argument: what to call it in the error (``"name"``, ``"geo_reference"``, a design-file field).
        limit: the largest number of characters.
        multiline: also allow newlines and tabs.

    Raises:
        ValueError: not a string, empty or only spaces, longer than ``limit``,
            or holding a refused character (named by its code point and position).
    """
    if not isinstance(value, str):
        raise ValueError(f"{argument} must be a string; got {type(value).__name__}")
    if not value.strip():
        raise ValueError(f"{argument} must hold a visible character; got {value!r:.80}")
    if len(value) > limit:
        raise ValueError(f"{argument} has {len(value)} characters; at most {limit} are allowed")
    for position, character in enumerate(value):
        if _refused(character, multiline):
            raise ValueError(f"{argument} must be printable text; it holds U+{ord(character):04X} at position {position}")
    return value


# ----------------------------------------------------------------- STEP

#: OCCT's STEP lexer ends a string at any ``'`` followed by blanks and ``)`` or ``,``.
_BEFORE_END = re.compile(r"[ \n\r]*[),]")


def _step_kind(item: tuple[int, str]) -> str:
    code = ord(item[1])
    return "ascii" if 0x20 <= code <= 0x7E else "X2" if code <= 0xFFFF else "X4"


def step_string(text: str) -> str:
    """A STEP string literal (ISO 10303-21 §6.3.3), quotes included, pure ASCII.

    ``'`` is doubled, except before blanks and ``)`` or ``,``, where it is
    written ``\\X2\\0027\\X0\\`` (OCCT's reader would end the string there);
    ``\\`` is doubled; each run of other characters outside printable ASCII
    becomes one ``\\X2\\`` (4 hex digits a character) or ``\\X4\\`` (8) directive.
    """
    out = ["'"]
    for kind, run in groupby(enumerate(text), key=_step_kind):
        if kind == "ascii":
            for position, character in run:
                if character == "'":
                    out.append("\\X2\\0027\\X0\\" if _BEFORE_END.match(text, position + 1) else "''")
                else:
                    out.append("\\\\" if character == "\\" else character)
        else:
            width = 4 if kind == "X2" else 8
            out.append(f"\\{kind}\\" + "".join(f"{ord(c):0{width}X}" for _, c in run) + "\\X0\\")
    out.append("'")
    return "".join(out)


# ----------------------------------------------------------------- IGES


def _ascii(character: str) -> str:
    if " " <= character <= "~":
        return character
    base = [c for c in unicodedata.normalize("NFKD", character) if not unicodedata.combining(c)]
    return base[0] if len(base) == 1 and " " <= base[0] <= "~" else "?"


def iges_text(text: str) -> str:
    """``text`` in IGES's 7-bit ASCII, one character for one: accents dropped (é → e), any
    other character outside printable ASCII as ``?``."""
    return "".join(map(_ascii, text))


# ------------------------------------------------------------------ DXF

#: Characters AutoCAD and ezdxf refuse in layer (table) names.
DXF_REFUSED = frozenset('<>/\\":;?*|=`')


def dxf_layer_name(name: str) -> str:
    """``name`` as a DXF layer name: refused characters as ``_``, outer spaces removed, and
    ``Defpoints`` (a layer CAD systems never plot) as ``Defpoints_``."""
    layer = "".join("_" if c in DXF_REFUSED else c for c in name).strip()
    return layer + "_" if layer.casefold() == "defpoints" else layer


# ------------------------------------------------------------------ XML

_NAME_START = (
    "A-Z_a-z\u00c0-\u00d6\u00d8-\u00f6\u00f8-\u02ff\u0370-\u037d\u037f-\u1fff\u200c-\u200d"
    "\u2070-\u218f\u2c00-\u2fef\u3001-\ud7ff\uf900-\ufdcf\ufdf0-\ufffd\U00010000-\U000effff"
)
_NOT_NAME_CHAR = re.compile(f"[^{_NAME_START}\\-.0-9\u00b7\u0300-\u036f\u203f-\u2040]")


def xml_id(name: str) -> str:
    """``name`` as an XML ``id`` (an NCName): other characters as ``_``, a leading ``_`` when it
    does not start with a letter or ``_``."""
    text = _NOT_NAME_CHAR.sub("_", name)
    return text if re.match(f"[{_NAME_START}]", text) else "_" + text
