"""Turn a model file (URDF or xacro) into URDF text, and resolve mesh URIs for PyBullet.

xacro 1.13.3 (the ROS 1 one) runs in-process through its API, so ``$(find pkg)`` works through rospkg and
``$(arg name)`` through the mappings we pass; nothing is shelled out. xacro and rospkg are imported
lazily so the rest of the package stays importable without them.
"""
import os

from diffbot_sim.description import xacro_compat, xml_documents
from diffbot_sim.errors import ModelError


def parse_args(text):
    """``"a:=1 b:=x"`` -> {"a": "1", "b": "x"} (xacro's command-line mapping syntax)."""
    mappings = {}
    for token in text.split():
        name, sep, value = token.partition(":=")
        if not sep or not name:
            raise ModelError(f"xacro argument '{token}' is not name:=value", "~model_args")
        mappings[name] = value
    return mappings


def load_file(path, args=None):
    """Read ``path``; run xacro on it when it is a .xacro file. Returns URDF text.

    xacro is 1.13.3 patched by ``xacro_compat`` (noetic's ``xacro.``/``python.``/``math.`` symbols, safe
    ``load_yaml``, noetic's macro defaults, ``$(dirname)``), so noetic descriptions load as they do in ROS.

    Raises:
        ModelError: the file is missing or unreadable, xacro fails, or the installed xacro is not the
            1.13.x the compatibility layer patches (the message names the file).
    """
    if not os.path.isfile(path):
        raise ModelError("no such file", path)
    if not path.endswith(".xacro"):
        try:
            with open(path, encoding="utf-8") as handle:
                return xml_documents.document_start(handle.read())  # blank lines before <?xml, as TinyXML
        except (OSError, UnicodeDecodeError) as err:
            raise ModelError(f"cannot read ({err})", path) from None
    xacro = xacro_compat.apply()  # lazy import of xacro: only xacro files need it; idempotent

    try:
        doc = xacro.process_file(path, mappings=dict(args or {}))
        return doc.toprettyxml(indent="  ")
    except Exception as err:  # xacro raises XacroException, ExpatError, IOError, NameError...
        detail = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ModelError(f"xacro failed: {detail}", path) from None
    finally:
        # xacro 1.13 keeps processing state in module globals; leave them clean for the next call.
        for name in ("filestack", "macrostack"):
            if hasattr(xacro, name):
                setattr(xacro, name, None if name == "filestack" else [])
        if hasattr(xacro, "all_includes"):
            xacro.all_includes = []


def package_path(package):
    """rospkg's path of ROS package ``package``, for ``package://`` URIs.

    Raises:
        LookupError: no such package on ROS_PACKAGE_PATH.
    """
    import rospkg  # lazy

    try:
        return rospkg.RosPack().get_path(package)
    except rospkg.ResourceNotFound as err:
        raise LookupError(package) from err
