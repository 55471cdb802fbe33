"""The project's exception hierarchy.

Every error a user can cause (a bad model file, a bad parameter, no terminal) is one of these, and its
message names the culprit (file, element path, joint or parameter) in one line, so a node's ``main()`` can
log it and exit non-zero without a traceback.
"""


class DiffbotSimError(Exception):
    """Base class of every error this package raises on purpose."""


class ModelError(DiffbotSimError):
    """The robot description is unusable: missing file, xacro error, bad XML, inconsistent elements.

    Args:
        message: what is wrong.
        source: the file (or ``robot_description``) the model came from.
        element: an XPath-like location, e.g. ``/robot/transmission[@name='left_trans']/joint``.
    """

    def __init__(self, message, source=None, element=None):
        self.source = source
        self.element = element
        where = ": ".join(part for part in (source, element) if part)
        super().__init__(f"{where}: {message}" if where else message)


class ConfigError(DiffbotSimError):
    """A parameter (ROS param or plugin tag) has a value that cannot be used.

    Args:
        name: the parameter, e.g. ``~time_step`` or ``<wheel_diameter>``.
        value: the offending value.
        expected: what would be valid, e.g. ``a finite number > 0``.
    """

    def __init__(self, name, value, expected):
        self.name = name
        self.value = value
        self.expected = expected
        super().__init__(f"parameter {name}: got {value!r}, expected {expected}")


class PluginNotLoaded(ModelError):
    """A plugin Gazebo would not load while loading the rest of the robot (its link is not in the model): the
    simulator warns once, naming it, and goes on without it, as Gazebo does."""


class TerminalError(DiffbotSimError):
    """The keyboard teleop cannot use standard input as a terminal."""
