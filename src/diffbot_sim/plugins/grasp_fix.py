"""``libgazebo_grasp_fix.so`` (JenniferBuehler/gazebo-pkgs' GazeboGraspFix): an object gripped from opposing
sides long enough is held to the palm by a fixed joint, and let go when its contact points move away, for
models whose grippers cannot hold objects by friction in ODE.

Its decisions are :mod:`diffbot_sim.control.grasp_fix` (CheckGrip, grip counts, attach to the arm with most
links in contact, release on moved contact points). Contacts of the gripper links with non-static bodies are
gathered every physics step and judged every ``1/update_rate`` s of sim time (upstream throttles by wall time,
which would make a run's grasps depend on the machine's speed). ``disable_collisions_on_attach`` turns the
held object's collisions with the robot off while attached, as upstream.
"""
from diffbot_sim.control.grasp_fix import GraspContact, GraspFixCore, grasp_contact, grasp_fix_config
from diffbot_sim.errors import PluginNotLoaded
from diffbot_sim.plugins.base import Plugin


class GraspFix(Plugin):
    filename = "libgazebo_grasp_fix.so"

    def __init__(self, ctx, cfg, path):
        self.ctx, self.cfg, self.path = ctx, cfg, path
        self.core = GraspFixCore(cfg)
        self.links = sorted({link for arm in cfg.arms for link in arm.gripper_links})
        self.contacts: list[GraspContact] = []  # raw contacts since the last decision
        self.joints_held: dict[tuple[str, tuple[int, int]], object] = {}  # (arm, object) -> physics handle
        self.next_decision = 0.0
        ctx.warnings.extend(cfg.notes)

    def next_control(self):
        return self.ctx.sim.sim_time

    def start(self, now):
        super().start(now)
        self.next_decision = now

    def after_step(self, now, stamp, transforms):
        robot, world = self.ctx.robot, self.ctx.sim.world
        touching = robot.link_contacts(self.links)  # most steps: none, and nothing more to do until a decision
        dynamic = set()
        if touching:
            dynamic = {uid for uid, body in world.world_bodies if not body.static}
            dynamic |= {r.body for r in world.robots if r is not robot}
        step: dict[tuple[str, tuple[int, int]], tuple[list, list]] = {}  # (link, object) -> (points, forces)
        for link, other, other_link, point, force in touching:
            if other in dynamic:
                entry = step.setdefault((link, (other, other_link)), ([], []))
                entry[0].append(point)
                entry[1].append(force)
        for (link, obj), (points, forces) in step.items():
            self.contacts.append(grasp_contact(link, obj, points, forces, robot.body_origin(*obj),
                                               robot.link_pose(link)))
        if now + 1e-9 < self.next_decision:
            return
        self.next_decision = now + self.cfg.update_period
        objects = {obj for _, obj in self.joints_held}
        actions = self.core.update(self.contacts, {link: robot.link_pose(link) for link in self.links},
                                   {obj: robot.body_origin(*obj) for obj in objects})
        self.contacts = []
        for action in actions:
            if action[0] == "attach":
                _, arm, obj, palm = action
                self.joints_held[(arm, obj)] = robot.attach(palm, obj[0], obj[1],
                                                            collide=not self.cfg.disable_collisions_on_attach)
            else:
                _, arm, obj = action
                handle = self.joints_held.pop((arm, obj), None)
                if handle is not None:
                    robot.detach(handle)

    def reset(self, now):
        for handle in self.joints_held.values():
            self.ctx.robot.detach(handle)
        self.joints_held = {}
        self.core = GraspFixCore(self.cfg)

    def summary(self):
        return {"grasp_fix/arms": ",".join(arm.name for arm in self.cfg.arms)}


def create(ctx, element, path, params):
    """The plugin, or PluginNotLoaded (one warning) when no arm is complete, as upstream stays inactive."""
    cfg = grasp_fix_config(element, path)
    for arm in cfg.arms:
        for link in (arm.palm_link, *arm.gripper_links):
            if link not in ctx.model.links:
                raise PluginNotLoaded(f"arm '{arm.name}' names link '{link}', which the model does not have; "
                                      "GazeboGraspFix could not be loaded", element=path)
    return GraspFix(ctx, cfg, path)
