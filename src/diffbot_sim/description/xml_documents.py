"""XML documents as Gazebo's parsers take them (pure).

Gazebo 11 reads worlds, ``model.sdf`` and ``model.config`` through sdformat 9, which uses TinyXML; COLLADA
meshes, URDFs (urdfdom) and ``<transmission>`` tags (transmission_interface) go through TinyXML or tinyxml2
as well. Those parsers skip a UTF-8 byte-order mark and any whitespace before the first ``<``, so a world
file that starts with a blank line before ``<?xml ...?>`` loads in Gazebo. expat (ElementTree, minidom)
refuses it: "XML or text declaration not at start of entity". TinyXML also stops reading the document
level at the first thing that is not a tag, and reads further top-level elements and stray end tags without
complaint; what readers use is the first root element. expat refuses anything after the root ("junk after
document element", "invalid token").

:func:`document_start` gives the text from its first ``<`` (for callers that parse it themselves);
:func:`parse` parses it, and keeps only the root element when something follows it, if asked to. Error
positions are those of the text as given (the skipped lines counted).
"""
import xml.etree.ElementTree as ET
from xml.parsers import expat

#: What TinyXML's SkipWhiteSpace skips (C ``isspace``), as text and as bytes.
_WHITESPACE = " \t\n\r\v\f"
_BOM = "\ufeff"
_BOM_BYTES = _BOM.encode("utf-8")


def _skipped(data):
    """How many leading characters (bytes for bytes) a TinyXML parser skips: a byte-order mark and
    whitespace."""
    if isinstance(data, bytes):
        rest = data[len(_BOM_BYTES):] if data.startswith(_BOM_BYTES) else data
        rest = rest.lstrip(_WHITESPACE.encode("ascii"))
    else:
        rest = data[len(_BOM):] if data.startswith(_BOM) else data
        rest = rest.lstrip(_WHITESPACE)
    return len(data) - len(rest)


def document_start(data):
    """``data`` (str or bytes) from its first non-blank character: a leading byte-order mark and whitespace
    dropped, as TinyXML drops them before an ``<?xml ...?>`` declaration that expat wants first."""
    return data[_skipped(data):]


def _shifted(err, prefix):
    """``err`` (an ET.ParseError of the text after ``prefix``) with its line and column in the whole text."""
    line, column = err.position
    newline = b"\n" if isinstance(prefix, bytes) else "\n"
    if line == 1:
        column += len(prefix) - (prefix.rfind(newline) + 1)
    line += prefix.count(newline)
    detail = str(err).rsplit(": line ", 1)[0]
    moved = ET.ParseError(f"{detail}: line {line}, column {column}")
    moved.code, moved.position = err.code, (line, column)
    return moved


def _root_end(data):
    """The offset in ``data`` just after its root element's end tag, or None when the root never closes."""
    raw = data.encode("utf-8") if isinstance(data, str) else data
    parser = expat.ParserCreate("UTF-8") if isinstance(data, str) else expat.ParserCreate()
    depth, end = [0], []

    def start(_name, _attributes):
        depth[0] += 1

    def stop(_name):
        depth[0] -= 1
        if depth[0] == 0 and not end:
            at = parser.CurrentByteIndex  # an end tag's '</'; just after an empty element's '/>'
            end.append(raw.index(b">", at) + 1 if raw.startswith(b"</", at) else at)

    parser.StartElementHandler, parser.EndElementHandler = start, stop
    try:
        parser.Parse(raw, True)
    except expat.ExpatError:
        pass
    if not end:
        return None
    return len(raw[:end[0]].decode("utf-8")) if isinstance(data, str) else end[0]


def parse(data, after_root=None):
    """The ElementTree root of the XML document ``data`` (str or bytes), read as TinyXML reads it: a leading
    byte-order mark and whitespace skipped.

    Args:
        after_root: None: anything after the root element is an error, as expat has it. A callable: what
            follows the root is ignored, as TinyXML ignores it, and ``after_root(line)`` is called with the
            line it starts on.

    Raises:
        ET.ParseError: not well-formed; its ``position`` and message give the line and column in ``data``.
    """
    skip = _skipped(data)
    prefix, body = data[:skip], data[skip:]
    try:
        return ET.fromstring(body)
    except ET.ParseError as err:
        error = _shifted(err, prefix)
    end = _root_end(body) if after_root is not None else None
    if end is None:  # not asked, or the error is inside the root element
        raise error
    try:
        root = ET.fromstring(body[:end])
    except ET.ParseError:  # a '>' inside an attribute value of the root's end: give up, as expat does
        raise error from None
    after_root(error.position[0])
    return root
