"""Finding a model's ``<sensor>`` by name, for plugins that read sensors they do not sit in (the Kobuki's bumper
and cliffs, the RealSense's four cameras), as Gazebo's SensorManager::GetSensor does."""


def find_sensor(model, name):
    """(element, link, path) of the model's ``<sensor name=...>``, or None."""
    for block in model.gazebo:
        for el in block.element.iter("sensor"):
            if el.get("name") == name:
                return el, block.reference, f"{block.path}/sensor[@name='{name}']"
    return None
