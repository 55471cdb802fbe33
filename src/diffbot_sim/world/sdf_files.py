"""The files an SDF world is read from (pure): parsing one (its XML, its SDF version) and finding the file an
``<include>`` or a mesh URI names, as Gazebo classic finds it. Nothing is ever downloaded.

Apart from :mod:`diffbot_sim.world.sdf_reader`'s scope of names and frames, so that what a URI means is
decided in one place: ``model://NAME`` is looked up in the search list (``~/.gazebo/models``, each
``GAZEBO_MODEL_PATH`` entry, then the directories ROS packages export to gazebo_ros,
:mod:`diffbot_sim.world.model_paths`), the first match winning; a model directory gives the SDF file its
``model.config`` names (the highest version this reader knows, as libsdformat picks); Gazebo's own
``ground_plane`` and ``sun`` are built in for when no directory has them. A model that cannot be found is an
error naming every directory searched.
"""
import os
import xml.etree.ElementTree as ET

from diffbot_sim.description import xml_documents
from diffbot_sim.errors import ModelError

#: The SDF versions this reader knows; others are read as the nearest one (with a warning).
VERSIONS = ((1, 4), (1, 5), (1, 6), (1, 7), (1, 8), (1, 9))
#: The parser's own version: ``model.config`` entries newer than this are skipped, as libsdformat does.
PARSER_VERSION = VERSIONS[-1]

# Gazebo installs exactly these two models with itself "to make Gazebo run without an internet
# connection" (the comment of gazebo-classic's models/CMakeLists.txt). Written from gazebo_models'
# ground_plane/model.sdf and sun/model.sdf: a static plane with ODE friction 100/50 and a directional light.
BUILTIN_MODELS = {
    "ground_plane": """<sdf version="1.5"><model name="ground_plane"><static>true</static>
  <link name="link"><collision name="collision"><geometry><plane><normal>0 0 1</normal><size>100 100</size>
  </plane></geometry><surface><friction><ode><mu>100</mu><mu2>50</mu2></ode></friction></surface></collision>
  <visual name="visual"><material><script><name>Gazebo/Grey</name></script></material></visual>
  </link></model></sdf>""",
    "sun": """<sdf version="1.5"><light type="directional" name="sun"><cast_shadows>true</cast_shadows>
  <pose>0 0 10 0 0 0</pose><diffuse>0.8 0.8 0.8 1</diffuse><specular>0.2 0.2 0.2 1</specular>
  <direction>-0.5 0.1 -0.9</direction></light></sdf>""",
}


class SdfFile:
    """One SDF file being read: its path (for messages and relative URIs) and its SDF version."""

    def __init__(self, path, version):
        self.path = path
        self.dir = os.path.dirname(path) if os.path.isabs(path) else os.getcwd()
        self.version = version


def parse_xml(path, text=None, warn=None):
    """ElementTree root of ``path`` (or of ``text``, labelled ``path``); a ModelError names file and line.

    Read as sdformat's TinyXML reads it (:mod:`diffbot_sim.description.xml_documents`): whitespace or a
    byte-order mark before ``<?xml`` is skipped, and with ``warn`` anything after the root element is
    ignored with one warning (Gazebo ignores it silently).
    """
    def after_root(line):
        warn(f"{path}: line {line}: text after the root element ignored, as Gazebo's parser ignores it")

    try:
        if text is None:
            with open(path, "rb") as handle:
                text = handle.read()
        return xml_documents.parse(text, after_root if warn else None)
    except ET.ParseError as err:
        line, column = err.position
        detail = str(err).split(":")[0]
        raise ModelError(f"malformed XML at line {line}, column {column + 1} ({detail})", path) from None
    except OSError as err:
        raise ModelError(f"cannot read ({err.strerror or err})", path) from None


def sdf_version(text):
    """``"1.6"`` -> (1, 6); None when it is not two dot-separated integers."""
    try:
        major, minor = (int(part) for part in (text or "").strip().split("."))
        return (major, minor)
    except ValueError:
        return None


class SdfFiles:
    """Reading SDF files and finding included ones for one world: ``search`` is the model directories in
    Gazebo's order (duplicates dropped, the first position wins, as Gazebo's InsertUnique); ``warn(text)``
    takes a warning for the world's report."""

    def __init__(self, model_paths, package_model_paths, warn):
        self.search = []
        for path in list(model_paths) + list(package_model_paths or []):
            if path and path not in self.search:
                self.search.append(path)
        self.warn = warn

    def load(self, path, text=None, label=None):
        """Parse an SDF file -> (root, _File). Version outside 1.4-1.9: warned, read as the nearest."""
        label = label or path
        root = parse_xml(label, text, self.warn) if text is not None else parse_xml(path, warn=self.warn)
        if root.tag != "sdf":
            raise ModelError(f"root element is <{root.tag}>, expected <sdf>", label, f"/{root.tag}")
        raw = root.get("version")
        version = sdf_version(raw)
        if version is None:
            self.warn(f"{label}: <sdf version='{raw or ''}'> is not a version; read as SDF 1.7 (Gazebo 11's)")
            version = (1, 7)
        elif version not in VERSIONS:
            nearest = VERSIONS[0] if version < VERSIONS[0] else VERSIONS[-1]
            self.warn(f"{label}: SDF {raw} is not one of 1.4-1.9; read as SDF {nearest[0]}.{nearest[1]}")
            version = nearest
        return root, SdfFile(label if text is not None else path, version)

    def model_file(self, directory, src, path):
        """The SDF file a model directory's model.config names (highest version <= 1.9; else the first)."""
        config = os.path.join(directory, "model.config")
        if not os.path.isfile(config):
            manifest = os.path.join(directory, "manifest.xml")
            if not os.path.isfile(manifest):
                raise ModelError(f"model directory {directory} has no model.config", src.path, path)
            self.warn(f"{manifest}: manifest.xml is deprecated in favour of model.config; read anyway")
            config = manifest
        root = parse_xml(config, warn=self.warn)
        entries = [(e.get("version"), (e.text or "").strip()) for e in root.iter("sdf") if (e.text or "").strip()]
        if not entries:
            raise ModelError("names no <sdf> file", config, "/model/sdf")
        versioned = [(sdf_version(v), name) for v, name in entries if sdf_version(v) is not None]
        if versioned:
            usable = [item for item in versioned if item[0] <= PARSER_VERSION]
            newer = [name for v, name in versioned if v > PARSER_VERSION]
            if usable:
                if newer:
                    self.warn(f"{config}: {', '.join(newer)} need SDF > 1.9 and are ignored")
                chosen = max(usable, key=lambda item: item[0])[1]
            else:
                chosen = min(versioned, key=lambda item: item[0])[1]
                self.warn(f"{config}: every file needs SDF > 1.9; reading {chosen} as 1.9")
        else:
            chosen = entries[0][1]
        target = os.path.join(directory, chosen)
        if not os.path.isfile(target):
            raise ModelError(f"names {chosen}, which does not exist", config, "/model/sdf")
        return target

    def resolve_include(self, uri, src, path):
        """Include ``uri`` -> an SDF file path, or ``("builtin", name)``. Never a download."""
        searched = []
        if uri.startswith(("http://", "https://")):
            raise ModelError(f"<include> uri '{uri}' is a network address; models are never downloaded "
                             f"(put the model in GAZEBO_MODEL_PATH)", src.path, path)
        if uri.startswith("model://"):
            rest = uri[len("model://"):].strip("/")
            name = rest.split("/", 1)[0]
            for directory in self.search:
                candidate = os.path.join(directory, rest)
                searched.append(directory)
                if os.path.exists(candidate):
                    return self.sdf_of(candidate, src, path)
            if rest in BUILTIN_MODELS:
                return ("builtin", rest)
            where = ", ".join(searched) if searched else "(no directory)"
            raise ModelError(f"cannot resolve <include> uri '{uri}': no directory '{name}' in any of {where} "
                             f"(models are never downloaded)", src.path, path)
        literal = uri[len("file://"):] if uri.startswith("file://") else uri
        candidates = [literal] if os.path.isabs(literal) else [os.path.join(src.dir, literal)]
        if not os.path.isabs(literal):
            candidates += [os.path.join(d, literal) for d in self.search]
        for candidate in candidates:
            if os.path.exists(candidate):
                return self.sdf_of(candidate, src, path)
        raise ModelError(f"cannot resolve <include> uri '{uri}': tried {', '.join(candidates)} "
                         f"(models are never downloaded)", src.path, path)

    def sdf_of(self, candidate, src, path):
        return os.path.abspath(self.model_file(candidate, src, path) if os.path.isdir(candidate) else candidate)

    def mesh_path(self, uri, src, path):
        """Mesh ``uri`` -> an absolute path, or None (warned) when no file is there."""
        tried = []
        if uri.startswith(("model://", "package://")):
            rest = uri.split("://", 1)[1].lstrip("/")
            tried = [os.path.join(d, rest) for d in self.search]
            if uri.startswith("package://"):
                package, _, inner = rest.partition("/")
                try:
                    import rospkg  # lazy, optional: Gazebo itself only searches the model paths

                    tried.append(os.path.join(rospkg.RosPack().get_path(package), inner))
                except Exception:  # rospkg missing or the package unknown: keep searching
                    pass
        else:
            literal = uri[len("file://"):] if uri.startswith("file://") else uri
            if os.path.isabs(literal):
                tried = [literal]
            else:
                tried = [os.path.join(src.dir, literal)]
                tried += [os.path.join(d, literal) for d in
                          os.environ.get("GAZEBO_RESOURCE_PATH", "").split(":") if d]
        for candidate in tried:
            if os.path.isfile(candidate):
                return os.path.abspath(candidate)
        self.warn(f"{src.path}: {path}: mesh '{uri}' not found (tried {', '.join(tried) or 'nothing'}); "
                  f"collision skipped")
        return None
