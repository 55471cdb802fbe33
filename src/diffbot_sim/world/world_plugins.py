"""The world plugins a world file names (``<world><plugin filename=...>``), for the few the simulator runs itself
(the link attacher). Pure: the file is read again, only for its top-level ``<world>``'s plugins."""
import xml.etree.ElementTree as ET


def world_plugins(path):
    """[(filename, name)] of the world file's world plugins, in file order; [] when it is not an SDF world."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError):
        return []
    world = root.find("world") if root.tag == "sdf" else (root if root.tag == "world" else None)
    if world is None:
        return []
    return [((p.get("filename") or "").strip(), p.get("name") or "") for p in world.findall("plugin")]
