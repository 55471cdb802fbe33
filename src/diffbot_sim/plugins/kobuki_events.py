"""The Kobuki plugin's events as the real base sends them (kobuki_msgs from the overlay): ``<base_prefix>/
events/bumper`` (BumperEvent), ``events/cliff`` (CliffEvent), ``events/wheel_drop`` (WheelDropEvent) and
``sensors/core`` (SensorState), each update of ``libgazebo_ros_kobuki.so`` (its ``update_rate``).

The plugin names its sensors by tag: ``bumper_name`` (a ``<sensor type="contact">``, :mod:`.bumper`'s
ContactSensor), ``cliff_sensor_left_name``/``_center_name``/``_right_name`` and ``cliff_detection_threshold``
(``<sensor type="ray">``s; the first ray's range), ``wheel_drop_left_sensor_name``/``_right_sensor_name``
(contact sensors on the wheels). A missing one is one warning and its events are not sent, as the original
logs and goes on. The decisions are :mod:`diffbot_sim.sensors.kobuki_events`.
"""
from diffbot_sim.plugins.base import join
from diffbot_sim.plugins.bumper import ContactSensor
from diffbot_sim.plugins.sensor_lookup import find_sensor
from diffbot_sim.sensors import kobuki_events as ev, ray as ray_sensor
from diffbot_sim.transforms import yaw_from_quaternion
from diffbot_sim.values import tag_number


class CliffSensor:
    """One cliff ray sensor: its first ray's range now."""

    def __init__(self, ctx, element, link, path):
        self.ctx, self.link = ctx, link
        self.cfg = ray_sensor.parse_sensor(element, path)
        self.pose, warning = ray_sensor.mounted_pose(self.cfg, ctx.model, link)
        if warning:
            ctx.warnings.append(warning)
        self.directions = ray_sensor.ray_directions(self.cfg)[:1]

    def range(self):
        cfg = self.cfg
        link_position, link_quaternion = self.ctx.robot.link_pose(self.link)
        position, rotation = ray_sensor.sensor_pose(link_position, link_quaternion, self.pose)
        starts, ends = ray_sensor.world_rays(position, rotation, self.directions, cfg.range_min, cfg.range_max)
        fractions, _, _ = self.ctx.sim.world.ray_batch(starts, ends)
        return float(ray_sensor.raw_ranges(fractions, cfg.range_min, cfg.range_max)[0])


class KobukiEvents:
    """The events of one Kobuki; ``update(stamp)`` on each of the plugin's updates."""

    def __init__(self, ctx, tags, path, ns, prefix):
        from kobuki_msgs import msg  # the overlay's; ImportError when it is left out

        self.ctx, self.msg = ctx, msg
        self.bumper = self._contact(tags, "bumper_name", path)
        self.wheels = [self._contact(tags, key, path) for key in ("wheel_drop_left_sensor_name",
                                                                   "wheel_drop_right_sensor_name")]
        self.cliffs = [self._cliff(tags, key, path) for key in ("cliff_sensor_left_name", "cliff_sensor_center_name",
                                                                 "cliff_sensor_right_name")]
        self.threshold = tag_number(f"<cliff_detection_threshold> of {path}", tags["cliff_detection_threshold"],
                                    ctx.warnings) if "cliff_detection_threshold" in tags else None
        if self.threshold is None and any(self.cliffs):
            ctx.warnings.append(f"{path}: no <cliff_detection_threshold>: no cliff events")
        self.bumper_edges, self.cliff_edges, self.drop_edges = ev.Edges(3), ev.Edges(3), ev.Edges(2)
        self.bumper_pub = ctx.publisher(join(ns, f"{prefix}/events/bumper"), msg.BumperEvent)
        self.cliff_pub = ctx.publisher(join(ns, f"{prefix}/events/cliff"), msg.CliffEvent)
        self.drop_pub = ctx.publisher(join(ns, f"{prefix}/events/wheel_drop"), msg.WheelDropEvent)
        self.core_pub = ctx.publisher(join(ns, f"{prefix}/sensors/core"), msg.SensorState)

    def _contact(self, tags, key, path):
        found = find_sensor(self.ctx.model, tags[key]) if key in tags else None
        if found is None:
            self.ctx.warnings.append(f"{path}: <{key}> names no sensor of the model: its events are not sent")
            return None
        return ContactSensor(self.ctx, found[0], found[1], found[2])

    def _cliff(self, tags, key, path):
        found = find_sensor(self.ctx.model, tags[key]) if key in tags else None
        if found is None:
            self.ctx.warnings.append(f"{path}: <{key}> names no sensor of the model: no cliff events from it")
            return None
        return CliffSensor(self.ctx, *found)

    def publishers(self):
        return [self.bumper_pub, self.cliff_pub, self.drop_pub, self.core_pub]

    def update(self, stamp):
        msg = self.msg
        if self.threshold is not None:
            ranges = [c.range() if c is not None else 0.0 for c in self.cliffs]
            for index, cliff in self.cliff_edges.update([r >= self.threshold for r in ranges]):
                self.cliff_pub.publish(msg.CliffEvent(sensor=index, state=ev.CLIFF if cliff else ev.FLOOR,
                                                      bottom=ev.cliff_bottom(ranges[index])))
        if self.bumper is not None:
            position, quaternion = self.ctx.robot.link_pose(self.ctx.model.root)  # the model's pose
            contacts = [(p.position[2], p.normal[0], p.normal[1], True) for p in self.bumper.points()]
            pressed = ev.bumper_sectors(contacts, position[2], yaw_from_quaternion(*quaternion))
            for index, on in self.bumper_edges.update(pressed):
                self.bumper_pub.publish(msg.BumperEvent(bumper=index, state=ev.PRESSED if on else ev.RELEASED))
        if all(self.wheels):
            dropped = [not w.points() for w in self.wheels]
            for index, on in self.drop_edges.update(dropped):
                self.drop_pub.publish(msg.WheelDropEvent(wheel=index, state=ev.DROPPED if on else ev.RAISED))
        bumper, cliff, drop = ev.sensor_state_bits(self.bumper_edges.states, self.cliff_edges.states,
                                                   self.drop_edges.states)
        if self.core_pub.get_num_connections():
            state = msg.SensorState(bumper=bumper, cliff=cliff, wheel_drop=drop)
            state.header.stamp = stamp
            self.core_pub.publish(state)
