"""Values from parameters and tags, checked in one place (pure): numbers, booleans and strings, and the
numbers of Gazebo tags read as Gazebo reads them.

Private parameters arrive typed from the parameter server and are checked strictly. Gazebo tags are text:

Gazebo reads every value of an SDF world and of a URDF's ``<gazebo>`` extension blocks (surface tags such as
``<mu1>``, sensor elements such as ``<samples>``, plugin tags such as ``<updateRate>``) with C++'s leniency:
sdformat's Param parses a double with ``std::stod`` and an unsigned int with ``std::stoul``, and plugins read
their tags through ``sdf::Element::Get<T>``, a stringstream ``>>``. All of them skip leading white space, take
the *leading* number and ignore the rest: a xacro-computed ``<samples>666.5185185185185</samples>`` is 666
beams (a published robot has it), ``<updateRate>50.0Hz</updateRate>`` is 50. A text without a leading number
is an error there, and here.

The URDF itself (``<origin xyz>``, ``<mass value>``, ``<limit effort>``) is read by urdfdom, strictly: not
here. Vectors (``<pose>``, noise vectors) are read strictly too: a stream of several numbers has no single
"leading number", and published models write them cleanly.
"""
import math
import re

from diffbot_sim.errors import ConfigError

# std::stod: decimal with optional exponent, or inf/infinity/nan (any case), after optional white space.
_DOUBLE = re.compile(r"\s*([+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan))", re.IGNORECASE)
# std::stoul / std::stoi in base 10: digits after an optional sign.
_INTEGER = re.compile(r"\s*([+-]?\d+)")


def leading_number(text, integer=False):
    """``(value, rest)``: the number ``text`` starts with, as ``std::stod`` (``integer``: ``std::stoi`` /
    ``std::stoul``) takes it, and what follows it (stripped; "" when nothing does).

    Raises:
        ValueError: ``text`` does not start with a number.
    """
    match = (_INTEGER if integer else _DOUBLE).match(text)
    if match is None:
        raise ValueError(f"no leading number in {text!r}")
    token = match.group(1)
    value = int(token) if integer else float(token)
    return value, text[match.end():].strip()


def tag_number(label, text, notes, integer=False, **limits):
    """The number in a Gazebo tag's ``text``, read as Gazebo does (:func:`leading_number`), then held to
    ``limits`` (``low``, ``high``, ``low_open``: see :func:`check_number`). What Gazebo drops
    after the number is dropped here too, with one line in ``notes`` naming ``label``. A value that is not
    text (a default, or a number already) is only checked against the limits.

    Raises:
        ConfigError: no leading number (naming ``label``), or a value out of ``limits``.
    """
    if not isinstance(text, str):
        number = check_number(label, text, **limits)
        return int(number) if integer else number
    try:
        value, rest = leading_number(text, integer)
    except ValueError:
        raise ConfigError(label, text, "a whole number" if integer else "a number") from None
    try:
        number = check_number(label, value, **limits)
    except ConfigError as err:
        raise ConfigError(label, text, err.expected) from None  # the text as written, not the number read
    if rest:
        reader = "std::stoul" if integer else "std::stod"
        notes.append(f"{label}: took {value:g} from '{text.strip()}', as Gazebo's SDF reader ({reader}) does")
    return int(number) if integer else number


def check_number(name, value, low=None, high=None, low_open=False):
    """``value`` as a finite float within ``low``/``high`` (``low_open``: above ``low``).

    Raises:
        ConfigError: not a number (a bool is not one), not finite, or out of range; naming ``name``.
    """
    if isinstance(value, bool):
        raise ConfigError(name, value, "a number")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ConfigError(name, value, "a number") from None
    if not math.isfinite(number):
        raise ConfigError(name, value, "a finite number")
    if low is not None and (number < low or (low_open and number == low)):
        raise ConfigError(name, value, f"a number {'>' if low_open else '>='} {low:g}")
    if high is not None and number > high:
        raise ConfigError(name, value, f"a number <= {high:g}")
    return number


def check_bool(name, value):
    """A bool, or the text true/false/1/0 (any case), as sdformat and ROS parameters spell them."""
    if isinstance(value, bool):
        return value
    text = str(value).strip().lower()
    if text in ("true", "1"):
        return True
    if text in ("false", "0"):
        return False
    raise ConfigError(name, value, "true or false")


def check_string(name, value, allow_empty=False):
    """A stripped string (non-empty unless ``allow_empty``)."""
    if not isinstance(value, str) or (not allow_empty and not value.strip()):
        raise ConfigError(name, value, "a non-empty string" if not allow_empty else "a string")
    return value.strip()


def check_mapping(name, value, expected="a dictionary"):
    """A namespace of parameters (a dict, as the parameter server hands one out): ``value`` itself, ``{}`` when
    it is absent (None), else ConfigError naming ``name`` and saying what was ``expected``."""
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise ConfigError(name, value, expected)
    return value
