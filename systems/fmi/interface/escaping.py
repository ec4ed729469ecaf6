"""One way out for every name, label, description and number the FMUs' generated files hold, one point
per language; what cannot pass is refused with a ValueError naming it, before any file is written.

- C: string literals (c_string: octal escapes beyond printable ASCII), numbers (c_double: exact, NAN,
  HUGE_VAL), both blocks/core/generate_tables.py's, and identifiers (c_identifier); no free text goes into a
  comment.
- XML: every attribute and text of a document (xml_tree: what XML 1.0 cannot hold at all is refused,
  ElementTree escapes the rest); numbers as xs:double spells them (xml_double).
- Python: string literals (python_literal) and identifiers (python_identifier: no keyword).
- FMI variable names: the structured naming convention the model descriptions declare (fmi_name).

Only the standard library is imported: the build runs it.
"""
from __future__ import annotations

import keyword
import math
import re
from xml.etree.ElementTree import Element

from attitude_fmu.blocks.core.generate_tables import C_KEYWORDS, c_double, c_string

# FMI 2.0 §2.2.9 (FMI 3.0 §2.4.7.5 alike): B-name [indices] {"." B-name [indices]}, a B-name a C-like identifier
# or a quoted Q-name of printable ASCII with the escapes \' \" \? \\ \a \b \f \n \r \t \v
_Q_CHAR = r"[A-Za-z0-9_!#$%&()*+,\-./:;<>=?@\[\]^{}|~ ]"
_B_NAME = rf"(?:[A-Za-z_][A-Za-z0-9_]*|'(?:{_Q_CHAR}|\\['\"?\\abfnrtv])+')"
_INDICES = r"(?:\[[0-9]+(?:,[0-9]+)*\])"
STRUCTURED = re.compile(rf"{_B_NAME}{_INDICES}?(?:\.{_B_NAME}{_INDICES}?)*")
# what XML 1.0 cannot hold, not even as a character reference (its production Char)
NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def fmi_name(name: str) -> str:
    """name, if it is a variable name of FMI's structured naming convention (gyr_x, block.A[0,1], 'a<b');
    ValueError otherwise."""
    if not (isinstance(name, str) and STRUCTURED.fullmatch(name)):
        raise ValueError(f"{name!r} is no FMI variable name (structured naming: letters, digits and _ joined by '.', "
                         f"indices such as [0,1], or a quoted 'name' of printable ASCII): rename that signal")
    return name


def xml_text(text: str, what: str) -> str:
    """text, if XML 1.0 can hold it (no control character but tab and line ends, no lone surrogate);
    ValueError naming what otherwise."""
    bad = NOT_XML.search(text)
    if bad:
        raise ValueError(f"{what} holds the character U+{ord(bad.group()):04X}, which XML cannot hold: "
                         f"{text[:80]!r}")
    return text


def xml_tree(root: Element, what: str) -> Element:
    """root, if XML 1.0 can hold every tag, attribute and text of the tree (xml_text); ValueError naming
    what and the attribute otherwise."""
    for node in root.iter():
        for part, text in [("text", node.text), ("tail", node.tail), *node.attrib.items()]:
            if text is not None:
                xml_text(text, f"{what}: {node.tag} {part}")
    return root


def xml_double(value: float) -> str:
    """value as xs:double spells it, exactly (shortest round trip; NaN, INF, -INF)."""
    if math.isnan(value):
        return "NaN"
    if math.isinf(value):
        return "INF" if value > 0 else "-INF"
    return repr(float(value))


def c_identifier(name: str, what: str) -> str:
    """name, if it is a C identifier (ASCII, no C99 keyword); ValueError naming what otherwise."""
    if not (isinstance(name, str) and name.isascii() and name.isidentifier() and name not in C_KEYWORDS):
        raise ValueError(f"{what} must be a C identifier, got {name!r}")
    return name


def python_identifier(name: str, what: str) -> str:
    """name, if it is an ASCII Python identifier and no keyword; ValueError naming what otherwise."""
    if not (isinstance(name, str) and name.isascii() and name.isidentifier() and not keyword.iskeyword(name)):
        raise ValueError(f"{what} must be a Python identifier (no keyword), got {name!r}")
    return name


def python_literal(text: str) -> str:
    """text as a Python string literal that evaluates to it (any text: quotes, line ends, control
    characters and lone surrogates escaped)."""
    return ascii(str(text))


__all__ = ["C_KEYWORDS", "c_double", "c_identifier", "c_string", "fmi_name", "python_identifier", "python_literal",
           "xml_double", "xml_text", "xml_tree"]
