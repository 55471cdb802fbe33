"""``libhector_gazebo_ros_sonar.so`` (hector_gazebo_plugins, on a ``<sensor type="ray">``): sensor_msgs/Range of
the sensor's rays, as :mod:`diffbot_sim.plugins.range` publishes gazebo_ros_range's, with hector's tags:
``topicName`` (default ``sonar``), ``frameId`` (default the sensor's link), ``gaussianNoise``, ``updateRate``;
radiation ULTRASOUND. hector's other noise-model tags (offset, drift, scale error) are ignored with one
warning."""
import copy
import xml.etree.ElementTree as ET

from diffbot_sim.plugins import range as range_plugin

_TAGS = {"frameId": "frameName", "topicName": "topicName", "gaussianNoise": "gaussianNoise",
         "updateRate": "updateRate", "robotNamespace": "robotNamespace"}


def create(ctx, sensor, element, params):
    adapted = ET.Element("plugin", dict(element.attrib))
    ignored = []
    for child in element:
        if child.tag in _TAGS:
            new = copy.deepcopy(child)
            new.tag = _TAGS[child.tag]
            adapted.append(new)
        elif child.tag not in ("alwaysOn",):
            ignored.append(child.tag)
    if adapted.find("topicName") is None:
        ET.SubElement(adapted, "topicName").text = "sonar"
    if adapted.find("frameName") is None:
        ET.SubElement(adapted, "frameName").text = sensor.link or ctx.model.root
    ET.SubElement(adapted, "radiation").text = "ultrasound"
    if ignored:
        ctx.warnings.append(f"{sensor.path}: hector sonar tags not simulated: {', '.join(ignored)}")
    plugin = range_plugin.create(ctx, sensor, adapted, params)
    plugin.filename = "libhector_gazebo_ros_sonar.so"
    return plugin
