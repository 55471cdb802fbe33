"""Where a robot's ros_control controllers are on the parameter server (pure: works on the parameter tree
as a nested dict, as ``rospy.get_param('/')`` or a controller YAML gives it).

Used by the gazebo_ros_control plugin (on the live server) and by robot_check (on the user's YAML files), so
both find the same controllers.
"""


def _subtree(tree, namespace):
    node = tree
    for part in [p for p in namespace.split("/") if p]:
        node = node.get(part) if isinstance(node, dict) else None
    return node if isinstance(node, dict) else {}


def find_controllers(tree, namespace):
    """{controller namespace: parameters} of every dict with a ``pkg/Type`` under ``namespace``; none there:
    anywhere in ``tree`` (a launch file that namespaced its controllers). ``gazebo_ros_control`` (its
    pid_gains) is not a controller."""
    def walk(prefix, node, out):
        if not isinstance(node, dict):
            return
        if isinstance(node.get("type"), str) and "/" in node["type"]:
            out[prefix] = node
            return
        for key, value in node.items():
            if key != "gazebo_ros_control":
                walk(prefix.rstrip("/") + "/" + key, value, out)

    ns = "/" + namespace.strip("/")
    found = {}
    walk(ns, _subtree(tree, ns), found)
    if not found and ns != "/":
        walk("/", tree, found)
    return found
