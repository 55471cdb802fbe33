"""gazebo_ros's world API (ROS 1 ``gazebo_ros_api_plugin``) served by the simulator, under ``~gazebo_namespace``
(``/gazebo``), with gazebo_msgs' own types (built in the workspace from the overlay package).

Services: spawn_urdf_model, spawn_sdf_model, delete_model, get_model_state, set_model_state,
get_world_properties, get_model_properties, get_link_state, set_link_state, get_physics_properties,
set_physics_properties, set_model_configuration, apply_body_wrench, clear_body_wrenches, pause_physics,
unpause_physics, reset_simulation, reset_world. Topics: model_states and link_states (every physics step,
only while subscribed, as Gazebo), set_model_state and set_link_state (in).

Every request runs on the simulator's loop (``Simulator.call``), the one thread that touches the physics; a
bad request gets ``success: false`` and a ``status_message`` naming the problem, and the loop goes on.
Models are the robots (spawned or started with the node) and the top-level models of the world file; a
link is ``model::link``.
"""
import math
import os
import tempfile

import rospy
from gazebo_msgs import msg as gmsg, srv as gsrv
from std_srvs.srv import Empty

from diffbot_sim.config import MAX_TIME_STEP, MIN_TIME_STEP
from diffbot_sim.description import meshes
from diffbot_sim.description.model_files import package_path
from diffbot_sim.errors import DiffbotSimError
from diffbot_sim.gazebo import model_xml, world_api
from diffbot_sim.gazebo.world_api import RequestError
from diffbot_sim.messages import gazebo as gazebo_messages
from diffbot_sim.plugins.base import close_handle, publisher
from diffbot_sim.simulator.gazebo_models import (
    ActorModelEntity,
    GhostModelEntity,
    RobotModelEntity,
    WorldModelEntity,
)
from diffbot_sim.simulator.joint_services import JointServices
from diffbot_sim.simulator.loop_requests import CALL_TIMEOUT
from diffbot_sim.transforms import compose

#: Time a spawn may take on the loop (mesh conversion of a large model), before the caller gives up.
SPAWN_TIMEOUT = 60.0


class GazeboApi:
    """The /gazebo services and topics. ``spawn_urdf(name, urdf_text, source, pose)`` builds a robot on the
    loop (every plugin, sensor and controller it would get at start) and returns its RobotRuntime."""

    def __init__(self, sim, spawn_urdf):
        self.sim = sim
        self.cfg = sim.cfg
        self.spawn_urdf = spawn_urdf
        self.ns = sim.cfg.gazebo_namespace.rstrip("/")
        self.wrenches = world_api.WrenchSchedule()
        self.seq = {}
        self.model_states_pub = publisher(self.ns + "/model_states", gmsg.ModelStates)
        self.link_states_pub = publisher(self.ns + "/link_states", gmsg.LinkStates)
        self.handles = []
        self.joints = JointServices(self)
        self.ghosts = {}  # name -> GhostModelEntity: spawned models without bodies
        self._models = None  # {name: entity}, built on first use and again after a spawn or a delete
        self._changed = False  # a spawn or delete since model_states was last published

    # -- the loop's side (called on its thread, like a plugin) --------------------------------------
    def publishers(self):
        return [self.model_states_pub, self.link_states_pub]

    def next_publish(self):
        """Every step while someone listens (Gazebo publishes on every world update), else never."""
        if self.model_states_pub.get_num_connections() or self.link_states_pub.get_num_connections():
            return self.sim.sim_time
        return math.inf

    def busy(self):
        """Wrenches or joint efforts are being applied: they last one step, so every step needs this API."""
        return bool(len(self.wrenches) or len(self.joints.efforts))

    def before_step(self, now):
        """Wrenches and joint efforts due during the coming step (Gazebo's schedulers run at the time the step
        reaches)."""
        self.joints.before_step(now)
        if not len(self.wrenches):
            return
        for body, force, torque, point in self.wrenches.active(now + self.cfg.time_step):
            model, link = world_api.split_link_name(body)
            entity = self.models().get(model)
            try:
                uid, index = entity.body_of(link) if entity is not None else (None, None)
            except RequestError:  # the model changed since the request (a respawn without a body)
                uid = None
            if uid is None:
                self.wrenches.clear(body)
                continue
            self.sim.world.apply_wrench(uid, index, force, torque, point)

    def after_step(self, now, stamp):
        self._changed = False
        models = self._publish_model_states() if self.model_states_pub.get_num_connections() else None
        if self.link_states_pub.get_num_connections():
            models = models or self.models()
            self.link_states_pub.publish(gazebo_messages.link_states(
                (f"{name}::{link}", *entity.motion(link)) for name, entity in models.items()
                for link in entity.links()))

    def publish_if_changed(self, now, stamp):
        """While sim time is held (``~wait_for_nodes``), a spawn or delete is published in model_states at once:
        clients that wait for their model to appear (or go) there would otherwise wait for ever."""
        if self._changed and self.model_states_pub.get_num_connections():
            self._publish_model_states()
        self._changed = False

    def _publish_model_states(self):
        models = self.models()
        self.model_states_pub.publish(gazebo_messages.model_states(
            (name, *entity.motion()) for name, entity in models.items()))
        return models

    # -- models ------------------------------------------------------------------------------------
    def models(self):
        """{name: entity}: world-file models in file order, then robots in spawn order. Built once and again
        only after a spawn or a delete (model_states asks every step)."""
        if self._models is None:
            self._models = self._build_models()
        return self._models

    def _build_models(self):
        out = {}
        for uid, body in self.sim.world.world_bodies:
            out.setdefault(body.top_model, []).append((uid, body))
        models = {name: WorldModelEntity(name, bodies, self.sim.world) for name, bodies in out.items()}
        models.update(self.ghosts)
        for actor in self.sim.actors.actors if self.sim.actors is not None else ():
            models[actor.name] = ActorModelEntity(actor)
        for runtime in self.sim.robots:
            models[runtime.name] = RobotModelEntity(runtime)
        return models

    def reset(self):
        """reset_world / reset_simulation: models without bodies go back to their spawn poses too."""
        for ghost in self.ghosts.values():
            ghost.reset()

    def _model(self, name, what="model"):
        entity = self.models().get(name)
        if entity is None:
            raise RequestError(f"{what} '{name}' does not exist")
        return entity

    def _frame_motion(self, frame, what):
        """World (pose, linear, angular) of a reference frame: a model or a ``model::link``; None: world."""
        model, link = frame.rsplit("::", 1) if "::" in frame else (frame, None)
        entity = self.models().get(model)
        if entity is not None and (link is None or link in entity.links()):
            return entity.motion(link)  # an entity first, as upstream: a model named "map" wins
        if world_api.is_world_frame(frame):
            return None
        raise RequestError(f"{what} '{frame}' not found: not a model nor a model::link")

    def _relative(self, motion, frame_motion):
        pose, linear, angular = motion
        if frame_motion is None:
            return pose, (linear, angular)
        fpose, flin, fang = frame_motion
        return world_api.relative_state(pose, (linear, angular), fpose, (flin, fang))

    def _absolute(self, pose, twist, frame_motion):
        if frame_motion is None:
            return pose, twist
        fpose, flin, fang = frame_motion
        # SetModelState's convention for both services: the twist's directions are read in the frame's axes
        # (SetLinkState upstream subtracts the frame velocity unrotated, a bug not copied).
        return world_api.world_state(pose, twist, fpose, (flin, fang), world_api.SET_MODEL_STATE)

    # -- ROS side ------------------------------------------------------------------------------------
    def advertise(self):
        ns = self.ns

        def service(name, kind, handler):
            self.handles.append(rospy.Service(f"{ns}/{name}", kind, handler))

        service("spawn_urdf_model", gsrv.SpawnModel, lambda req: self._spawn(req, "urdf"))
        service("spawn_sdf_model", gsrv.SpawnModel, lambda req: self._spawn(req, "sdf"))
        service("delete_model", gsrv.DeleteModel, self._delete)
        service("get_model_state", gsrv.GetModelState, self._get_model_state)
        service("set_model_state", gsrv.SetModelState, self._set_model_state)
        service("get_world_properties", gsrv.GetWorldProperties, self._world_properties)
        service("get_model_properties", gsrv.GetModelProperties, self._model_properties)
        service("get_link_state", gsrv.GetLinkState, self._get_link_state)
        service("set_link_state", gsrv.SetLinkState, self._set_link_state)
        service("get_physics_properties", gsrv.GetPhysicsProperties, self._get_physics)
        service("set_physics_properties", gsrv.SetPhysicsProperties, self._set_physics)
        service("set_model_configuration", gsrv.SetModelConfiguration, self._set_configuration)
        service("apply_body_wrench", gsrv.ApplyBodyWrench, self._apply_wrench)
        service("clear_body_wrenches", gsrv.BodyRequest, self._clear_wrenches)
        self.joints.advertise(service)
        for name, action in (("pause_physics", self.sim.pause), ("unpause_physics", self.sim.unpause),
                             ("reset_simulation", self.sim.reset_simulation), ("reset_world", self.sim.reset_world)):
            service(name, Empty, lambda req, action=action: self.sim.empty_service(action, req))
        self.handles.append(rospy.Subscriber(f"{ns}/set_model_state", gmsg.ModelState, self._on_model_state,
                                             queue_size=10))
        self.handles.append(rospy.Subscriber(f"{ns}/set_link_state", gmsg.LinkState, self._on_link_state,
                                             queue_size=10))

    def _run(self, action, response, timeout=CALL_TIMEOUT):
        """Run ``action`` on the loop; fill ``response.success``/``status_message``; never raise for a bad
        request (the caller gets success false and the reason)."""
        try:
            result = self.sim.call(action, timeout)
            response.success = True
            response.status_message = result if isinstance(result, str) else "ok"
        except (RequestError, ValueError, DiffbotSimError) as err:
            response.success = False
            response.status_message = str(err)
            rospy.logwarn(f"{self.ns}: {response.status_message}")
        return response

    # spawn / delete
    def _spawn(self, req, service_kind):
        response = gsrv.SpawnModelResponse()
        return self._run(lambda: self._spawn_on_loop(req, service_kind), response, SPAWN_TIMEOUT)

    def _spawn_on_loop(self, req, service_kind):
        try:
            return self._spawn_checked(req, service_kind)
        finally:
            self._models = None  # a robot or bodies may have joined
            self._changed = True

    def _spawn_checked(self, req, service_kind):
        name = req.model_name
        if not name or "::" in name or "/" in name:
            raise RequestError(f"SpawnModel: model_name '{name}' is not a valid model name")
        if name in self.models():
            raise RequestError(f"SpawnModel: Failure - entity '{name}' already exists.")
        kind = model_xml.model_xml_kind(req.model_xml)
        pose = world_api.check_pose(gazebo_messages.pose_tuple(req.initial_pose), "initial_pose")
        frame = self._frame_motion(req.reference_frame, "reference_frame")
        if frame is not None:
            pose = compose(frame[0], pose)
        namespace = req.robot_namespace
        if kind == "urdf":
            text = model_xml.prepare_urdf(req.model_xml, package_path)
            text = model_xml.inject_robot_namespace(text, namespace)
            text = model_xml.rename_model(text, "urdf", name)
            runtime = self.spawn_urdf(name, text, f"{self.ns}/spawn_{service_kind}_model({name})", pose)
            return f"SpawnModel: Successfully spawned entity '{runtime.name}'"
        text = model_xml.inject_robot_namespace(req.model_xml, namespace)
        text = model_xml.rename_model(text, "sdf", name)
        count, links, placed_pose = self._spawn_sdf(name, text, pose)
        if count == 0:
            self.ghosts[name] = GhostModelEntity(name, placed_pose, links)
        return f"SpawnModel: Successfully spawned entity '{name}' ({count} bodies)"

    def _spawn_sdf(self, name, text, pose):
        """An SDF model becomes world bodies: the model's pose replaced by the request's, as Gazebo does."""
        from diffbot_sim.world.model_paths import ros_package_model_paths
        from diffbot_sim.world.sdf_reader import read_world
        placed = model_xml.sdf_model_at(text, pose)
        with tempfile.TemporaryDirectory(prefix="spawn_sdf_") as tmp:
            path = os.path.join(tmp, f"{name}.world")
            with open(path, "w") as out:
                out.write(f'<sdf version="1.7"><world name="spawn">{placed}</world></sdf>')
            world = read_world(path, package_model_paths=ros_package_model_paths())
        for text in world.warnings + [f"not simulated: {'; '.join(world.not_simulated)}"] * bool(world.not_simulated):
            rospy.logwarn(f"spawned model {name}: {text}")
        world.has_ground = False  # a spawned plane does not replace the ground
        count = self.sim.world.load_world(world, meshes.default_cache_dir())
        frame, links = model_xml.sdf_model_frame(placed)
        return count, links, frame

    def _delete(self, req):
        response = gsrv.DeleteModelResponse()

        def action():
            entity = self._model(req.model_name)
            if isinstance(entity, RobotModelEntity):
                self.sim.remove_robot(entity.runtime)
            elif isinstance(entity, GhostModelEntity):
                del self.ghosts[req.model_name]
            else:
                for uid, _ in entity.bodies:
                    self.sim.world.remove_body(uid)
            self._models = None
            self._changed = True
            self.wrenches.clear_model(req.model_name)
            return f"DeleteModel: successfully deleted model '{req.model_name}'"
        return self._run(action, response)

    # model and link state
    def _get_model_state(self, req):
        response = gsrv.GetModelStateResponse()

        def action():
            entity = self._model(req.model_name, "GetModelState: model")
            frame = self._frame_motion(req.relative_entity_name, "GetModelState: relative_entity_name")
            pose, twist = self._relative(entity.motion(), frame)
            self.seq[req.model_name] = self.seq.get(req.model_name, 0) + 1
            response.header = gazebo_messages.state_header(self.seq[req.model_name], self.sim.stamp(),
                                                           req.relative_entity_name)
            response.pose, response.twist = gazebo_messages.pose_msg(pose), gazebo_messages.twist_msg(twist)
            return "GetModelState: got properties"
        return self._run(action, response)

    def _set_state(self, name, link, pose_msg, twist_msg, frame_name):
        """SetModelState / SetLinkState on the loop: pose and twist relative to ``frame_name``."""
        entity = self._model(name, "SetModelState: model")
        if link is not None and link not in entity.links():
            raise RequestError(f"link '{name}::{link}' does not exist")
        pose = world_api.check_pose(gazebo_messages.pose_tuple(pose_msg), "pose")
        twist = world_api.check_twist(gazebo_messages.twist_tuple(twist_msg), "twist")
        frame = self._frame_motion(frame_name, "reference_frame")
        pose, (linear, angular) = self._absolute(pose, twist, frame)  # directions turned, as SetModelState
        entity.set_motion(pose, linear, angular, link)

    def _set_model_state(self, req):
        state = req.model_state
        return self._run(lambda: self._set_state(state.model_name, None, state.pose, state.twist,
                                                 state.reference_frame) or "SetModelState: set model state done",
                         gsrv.SetModelStateResponse())

    def _on_model_state(self, state):
        self.sim.post(lambda: self._set_state_logged(state.model_name, None, state.pose, state.twist,
                                                     state.reference_frame))

    def _on_link_state(self, state):
        model, link = self._split(state.link_name)
        self.sim.post(lambda: self._set_state_logged(model, link, state.pose, state.twist, state.reference_frame))

    def _set_state_logged(self, *args):
        try:
            self._set_state(*args)
        except (RequestError, ValueError) as err:
            self.sim.warn(f"set_state:{args[0]}", f"{self.ns}/set_model_state (topic): {err}")

    @staticmethod
    def _split(name):
        try:
            return world_api.split_link_name(name)
        except ValueError:
            return name, ""

    def _get_link_state(self, req):
        response = gsrv.GetLinkStateResponse()

        def action():
            model, link = world_api.split_link_name(req.link_name)
            entity = self._model(model, "GetLinkState: model")
            if link not in entity.links():
                raise RequestError(f"GetLinkState: link '{req.link_name}' does not exist")
            frame = self._frame_motion(req.reference_frame, "GetLinkState: reference_frame")
            pose, twist = self._relative(entity.motion(link), frame)
            response.link_state = gazebo_messages.link_state(req.link_name, pose, twist, req.reference_frame)
            return "GetLinkState: got state"
        return self._run(action, response)

    def _set_link_state(self, req):
        state = req.link_state

        def action():
            model, link = world_api.split_link_name(state.link_name)
            self._set_state(model, link, state.pose, state.twist, state.reference_frame)
            return "SetLinkState: success"
        return self._run(action, gsrv.SetLinkStateResponse())

    # properties
    def _world_properties(self, _req):
        response = gsrv.GetWorldPropertiesResponse()

        def action():
            response.sim_time = self.sim.sim_time
            response.model_names = list(self.models())
            response.rendering_enabled = True
            return "GetWorldProperties: got properties"
        return self._run(action, response)

    def _model_properties(self, req):
        response = gsrv.GetModelPropertiesResponse()

        def action():
            entity = self._model(req.model_name, "GetModelProperties: model")
            response.parent_model_name = ""
            response.body_names = entity.links()
            response.canonical_body_name = response.body_names[0] if response.body_names else ""
            if isinstance(entity, RobotModelEntity):
                model = entity.model
                response.canonical_body_name = model.root
                response.joint_names = [j.name for j in model.joints.values() if j.type != "fixed"]
                response.geom_names = [f"{link}_collision" for link in entity.links()]
            response.is_static = entity.static
            return "GetModelProperties: got properties"
        return self._run(action, response)

    def _get_physics(self, _req):
        response = gsrv.GetPhysicsPropertiesResponse()

        def action():
            cfg = self.cfg
            values = world_api.physics_properties(cfg.time_step, cfg.real_time_factor, cfg.real_time,
                                                  self.sim.paused, self.sim.world.gravity,
                                                  self.sim.world.solver_iterations)
            response.time_step = values["time_step"]
            response.pause = values["pause"]
            response.max_update_rate = values["max_update_rate"]
            response.gravity = gazebo_messages.vector3(values["gravity"])
            for key, value in values["ode_config"].items():
                setattr(response.ode_config, key, value)
            return "GetPhysicsProperties: got properties"
        return self._run(action, response)

    def _set_physics(self, req):
        def action():
            cfg = self.cfg
            g = req.gravity
            if not all(math.isfinite(v) for v in (g.x, g.y, g.z, req.max_update_rate, req.time_step)):
                raise RequestError("SetPhysicsProperties: time_step, gravity and max_update_rate must be finite")
            if req.time_step and not MIN_TIME_STEP <= req.time_step <= MAX_TIME_STEP:
                raise RequestError(f"SetPhysicsProperties: time_step {req.time_step:g} s is outside "
                                   f"[{MIN_TIME_STEP:g}, {MAX_TIME_STEP:g}] s")
            if req.time_step and abs(req.time_step - cfg.time_step) > 1e-12:
                self.sim.set_time_step(req.time_step)  # before the rate: Gazebo's pace is rate x step
            iters = req.ode_config.sor_pgs_iters
            if iters > 0 and iters != self.sim.world.solver_iterations:
                self.sim.world.set_solver_iterations(iters)
            if abs(g.x) > 1e-12 or abs(g.y) > 1e-12:
                rospy.logwarn(f"{self.ns}/set_physics_properties: horizontal gravity is not simulated")
            self.sim.world.set_gravity(g.z)
            self.sim.set_update_rate(req.max_update_rate)
            return "SetPhysicsProperties: physics properties set"
        return self._run(action, gsrv.SetPhysicsPropertiesResponse())

    def _set_configuration(self, req):
        """SetModelConfiguration as upstream: unknown model or lists of different lengths refused; names the
        model does not move are ignored; positions clamped to the joints' limits (Gazebo's SetPosition);
        the robot's joints at rest there. Controllers keep their commands: a trajectory controller holding
        its start pose drives the joints back, as in Gazebo (gazebo_ros_pkgs #93), unless paused until they
        start (spawn_model -J ... -unpause)."""
        def action():
            entity = self.models().get(req.model_name)
            if entity is None:
                raise RequestError("SetModelConfiguration: model does not exist")
            if len(req.joint_names) != len(req.joint_positions):
                raise RequestError("SetModelConfiguration: joint name and position list have different lengths")
            if not isinstance(entity, RobotModelEntity):
                return "SetModelConfiguration: success"
            robot = entity.robot
            names, positions = [], []
            for joint, position in zip(req.joint_names, req.joint_positions):
                if joint in robot.joint_index and math.isfinite(position):
                    lower, upper = robot.joint_limits(robot.joint_index[joint])
                    names.append(joint)
                    positions.append(min(max(position, lower), upper) if lower <= upper else position)
            robot.set_joint_positions(robot.indices(names), positions)
            entity.runtime.ctx.sim.world.lift_out(robot)
            return "SetModelConfiguration: success"
        return self._run(action, gsrv.SetModelConfigurationResponse())

    # wrenches
    def _apply_wrench(self, req):
        def action():
            model, link = world_api.split_link_name(req.body_name)
            entity = self._model(model, "ApplyBodyWrench: body")
            if link not in entity.links():
                raise RequestError(f"ApplyBodyWrench: body '{req.body_name}' does not exist")
            frame = self._frame_motion(req.reference_frame, "ApplyBodyWrench: reference_frame")
            w = req.wrench
            force = (w.force.x, w.force.y, w.force.z)
            torque = (w.torque.x, w.torque.y, w.torque.z)
            point = (req.reference_point.x, req.reference_point.y, req.reference_point.z)
            if not all(math.isfinite(v) for v in force + torque + point):
                raise RequestError("ApplyBodyWrench: wrench and reference_point must be finite")
            entity.body_of(link)  # a model with no body to push (nothing collides) is refused now, not on the loop
            body_pose = entity.motion(link)[0]
            frame_pose = frame[0] if frame is not None else None
            force, torque, point = world_api.wrench_to_world(force, torque, point, frame_pose, body_pose)
            self.wrenches.add(req.body_name, force, torque, point, req.start_time.to_sec(),
                              req.duration.to_sec(), self.sim.sim_time)
            return ""
        return self._run(action, gsrv.ApplyBodyWrenchResponse())

    def _clear_wrenches(self, req):
        self.sim.call(lambda: self.wrenches.clear(req.body_name))
        return gsrv.BodyRequestResponse()

    def close(self):
        for handle in self.handles:
            close_handle(handle)
