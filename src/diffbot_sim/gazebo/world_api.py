"""gazebo_ros's world API, its decisions only (pure: no rospy, no PyBullet): what the ROS 1 (noetic)
``gazebo_ros_api_plugin`` does to frames, twists, model XML, wrenches and physics properties, so the ROS node
that serves ``/gazebo/*`` answers as Gazebo classic did.

Every rule here was read in ``gazebo_ros/src/gazebo_ros_api_plugin.cpp`` (gazebo_ros_pkgs, noetic-devel),
with ignition-math's ``Pose3``/``Quaternion`` and Gazebo's ``Base::GetByName``, ``World::Step`` and
``ODELink::SetForce`` where the plugin leans on them. Where upstream has a bug that a client can see, the
function either mirrors it and says so (the point is to behave like Gazebo) or, where mirroring would only
hang or corrupt, does the sensible thing and says that instead; each docstring names which.

Conventions: a pose is ``((x, y, z), (qx, qy, qz, qw))``, a twist ``((vx, vy, vz), (wx, wy, wz))``, both in
WORLD axes unless a name says otherwise; times are sim seconds (floats).
"""
import math

from diffbot_sim.gazebo.ignition import add, cross, floats, sub, unit, unit_pose, unrotate
from diffbot_sim.transforms import compose, inverse, rotate

# ------------------------------------------------------------------------------------------ frames

#: Reference-frame names every service (spawn, get/set model and link state, apply_body_wrench) takes for
#: the world, when no entity has that name: upstream tests an entity lookup first, then exactly these four.
WORLD_FRAMES = frozenset({"", "world", "map", "/map"})

#: Upstream's status_message when a reference frame is neither an entity nor a world name, per service.
FRAME_NOT_FOUND = {
    "spawn_model": "SpawnModel: reference reference_frame not found, did you forget to scope the link by "
                   "model name?",
    "get_model_state": "GetModelState: reference relative_entity_name not found, did you forget to scope the "
                       "body by model name?",
    "get_link_state": "GetLinkState: reference reference_frame not found, did you forget to scope the link by "
                      "model name?",
    "set_model_state": "SetModelState: specified reference frame entity does not exist",
    "set_link_state": "SetLinkState: failed",
    "apply_body_wrench": "ApplyBodyWrench: reference_frame not found",
}

#: ``world_state`` conventions: the exact inverse of ``relative_state``, or what each Set service does.
INVERSE, SET_MODEL_STATE, SET_LINK_STATE = "inverse", "set_model_state", "set_link_state"


def is_world_frame(name):
    """True for the names gazebo_ros reads as the inertial frame: "", "world", "map", "/map".

    The same four in every service (spawn, get/set model state, get/set link state, apply_body_wrench).
    Upstream looks the name up as an entity FIRST and only then compares it with these, so a model that is
    really called "map" or "world" is a frame there; a caller that wants that precedence looks its entities
    up before calling this.
    """
    return name in WORLD_FRAMES


def split_link_name(name):
    """``"model::link"`` -> ``("model", "link")``; a nested ``"a::b::c"`` -> ``("a::b", "c")``.

    Gazebo's scoped name of a link is its ancestors' names joined by ``::`` (the world left out), so the
    link is the last component and the model everything before it. Upstream also resolves a bare name
    (see :func:`find_entity`); this function is for callers that need the model part, so a bare name is a
    ValueError (with Gazebo's own hint about scoping).
    """
    model, sep, link = str(name).rpartition("::")
    if not sep:
        raise ValueError(f"'{name}' is not a scoped link name (model::link): did you forget to scope the link "
                         f"by model name?")
    if not model or not link or model.startswith("::") or model.endswith("::"):
        raise ValueError(f"'{name}' is not a scoped link name (model::link): a part is empty")
    return model, link


def find_entity(name, scoped_names):
    """The entity ``name`` resolves to, as Gazebo's ``World::EntityByName`` -> ``Base::GetByName`` does.

    ``scoped_names``: every entity's scoped name (models, nested models, links ...) in Gazebo's depth-first
    order (a model, then its children, in the order they were loaded). Upstream returns the first entity
    whose scoped name OR plain (last-component) name equals ``name``, so ``"base_link"`` alone finds the
    first model's base_link. Returns that scoped name, or None.
    """
    for scoped in scoped_names:
        if scoped == name or scoped.rpartition("::")[2] == name:
            return scoped
    return None


# ------------------------------------------------------------------------------------------ states

def relative_state(pose, twist, frame_pose, frame_twist):
    """What GetModelState (``relative_entity_name``) and GetLinkState (``reference_frame``) return for an
    entity at world ``pose``/``twist`` seen from the entity at ``frame_pose``/``frame_twist``.

    Pose: the entity's pose expressed in the frame (ignition ``entity_pose - frame_pose``; the quaternion
    comes back normalised). Twist, exactly as upstream: ``R_frameᵀ·(v − v_frame)`` and
    ``R_frameᵀ·(w − w_frame)``: world velocity differences turned into the frame's axes, WITHOUT the
    ``ω_frame × r`` transport term a rigid-body transform would add (a point at rest in the world, seen
    from a spinning frame, reports zero linear velocity).
    """
    pose, frame_pose = unit_pose(pose), unit_pose(frame_pose)
    qf = frame_pose[1]
    (v, w), (vf, wf) = (floats(c) for c in twist), (floats(c) for c in frame_twist)
    return compose(inverse(frame_pose), pose), (unrotate(qf, sub(v, vf)), unrotate(qf, sub(w, wf)))


def world_state(pose_in_frame, twist_in_frame, frame_pose, frame_twist, convention=INVERSE):
    """World pose and twist of a state given relative to a frame (SetModelState / SetLinkState with
    ``reference_frame``).

    The pose is always ``frame_pose ∘ pose_in_frame`` (ignition ``target_pose + frame_pose``). The twist
    depends on ``convention``, because upstream's two Set services disagree with each other and neither is
    the inverse of :func:`relative_state`:

    * ``INVERSE`` (default): the exact inverse of :func:`relative_state`, ``R_frame·v + v_frame`` and
      ``R_frame·w + w_frame``, so a state read with ``relative_state`` and written back lands where it was.
    * ``SET_MODEL_STATE``: what SetModelState does: ``R_frame·v`` and ``R_frame·w``; the frame's own velocity
      is NOT added ("velocities should be commanded in the requested reference frame": directions only).
    * ``SET_LINK_STATE``: what SetLinkState does: ``v − v_frame`` and ``w − w_frame``, NOT rotated (an
      upstream bug: the frame velocity is subtracted where it should be added, and the axes are the world's).
    """
    pose_in_frame, frame_pose = unit_pose(pose_in_frame), unit_pose(frame_pose)
    qf = frame_pose[1]
    (v, w), (vf, wf) = (floats(c) for c in twist_in_frame), (floats(c) for c in frame_twist)
    pose = compose(frame_pose, pose_in_frame)
    if convention == INVERSE:
        return pose, (add(rotate(qf, v), vf), add(rotate(qf, w), wf))
    if convention == SET_MODEL_STATE:
        return pose, (rotate(qf, v), rotate(qf, w))
    if convention == SET_LINK_STATE:
        return pose, (sub(v, vf), sub(w, wf))
    raise ValueError(f"world_state: convention '{convention}' is not one of "
                     f"{INVERSE!r}, {SET_MODEL_STATE!r}, {SET_LINK_STATE!r}")


def _finite(values, names, what):
    out = []
    for name, value in zip(names, values):
        value = float(value)
        if not math.isfinite(value):
            raise ValueError(f"{what}.{name} is {value!r}")
        out.append(value)
    return tuple(out)


def check_pose(pose, what):
    """``pose`` with finite numbers and a unit quaternion, or ValueError naming the field
    (``"initial_pose.position.x is nan"``).

    Upstream passes NaN and inf on to the physics (which then blows up); they are refused here. A zero (or
    near-zero: norm <= 1e-6) quaternion is accepted as the identity, as ignition's ``Quaternion::Normalize``
    makes it (SetModelState normalises explicitly "to eliminate invalid rotation (0, 0, 0, 0)"; spawn gets
    the same through ``Euler()``); any other quaternion is normalised.
    """
    p, q = pose
    position = _finite(p, ("position.x", "position.y", "position.z"), what)
    orientation = _finite(q, ("orientation.x", "orientation.y", "orientation.z", "orientation.w"), what)
    return position, unit(orientation)


def check_twist(twist, what):
    """``twist`` as floats, or ValueError naming the first non-finite field (``"twist.angular.z is inf"``)."""
    v, w = twist
    return (_finite(v, ("linear.x", "linear.y", "linear.z"), what),
            _finite(w, ("angular.x", "angular.y", "angular.z"), what))


# ------------------------------------------------------------------------------------------ wrenches

def wrench_to_world(force, torque, reference_point, frame_pose, body_pose=None):
    """(force, torque, point) to apply for an ApplyBodyWrench request, exactly as upstream computes it.

    Upstream first moves the wrench to the point: ``torque += reference_point × force`` (the point is a
    lever arm in the reference frame's axes, not a position). Then:

    * world frame (``frame_pose`` None: "", "world", "map", "/map"): force and that torque as they are.
    * an entity frame: ``tr = frame_pose - body_pose`` (the frame seen from the body); force ``R_tr·F``,
      torque ``R_tr·T + p_tr × (R_tr·F)``: the wrench expressed in the BODY's axes about the body origin.
      ``body_pose`` is required then.

    Either way upstream hands the result to ``Link::SetForce``/``SetTorque``, which in ODE are WORLD-axes
    force and torque at the link's CENTRE OF MASS. So with an entity frame the body-axes numbers are applied
    as world axes (upstream issue ros-simulation/gazebo_ros_pkgs#310, "Wrenches aren't transformed by
    reference frame"; it is only right while the body is aligned with the world). That is mirrored here.
    The returned point is always None: "at the link's centre of mass".
    """
    f, t, p = floats(force), floats(torque), floats(reference_point)
    t = add(t, cross(p, f))
    if frame_pose is None:
        return f, t, None
    if body_pose is None:
        raise ValueError("wrench_to_world: body_pose is needed with a reference frame")
    tr_p, tr_q = compose(inverse(unit_pose(body_pose)), unit_pose(frame_pose))
    f = rotate(tr_q, f)
    t = add(rotate(tr_q, t), cross(tr_p, f))
    return f, t, None


def _ns(seconds):
    """Seconds -> integer nanoseconds, as ``ros::Time(double)`` stores them, so comparisons are exact."""
    return int(round(float(seconds) * 1e9))


class RequestError(ValueError):
    """A /gazebo request refused with this status message (success false; the simulator goes on)."""


class WrenchSchedule:
    """apply_body_wrench / clear_body_wrenches jobs, timed as gazebo_ros's ``wrenchBodySchedulerSlot``.

    A job: (body, force, torque, point) from ``start`` for ``duration``. Timing, as upstream:

    * ``start_time`` earlier than now (0, the unset value, included) means now.
    * at a step whose sim time is ``t`` the job applies if ``t >= start`` and (``duration < 0`` or
      ``t <= start + duration``); it is dropped once ``t > start + duration`` (never when ``duration < 0``).
    * Gazebo runs the slot at WorldUpdateBegin, after ``World::Step`` has already advanced sim time: ``t``
      is the time the coming step will REACH, while "now" at request time is the time already reached. So
      ``duration = 0`` with start "now" never applies (the srv file's "if duration < step size, apply wrench
      for one step size" is not what the code does: any ``0 <= duration < step`` starting now does nothing);
      a duration ``d`` starting now acts for ``floor(d / step)`` steps; a future start exactly on a step
      time with duration 0 acts for one step.
    * Each job calls ``SetForce``/``SetTorque``, which REPLACE the link's force and torque, so of several
      jobs active on one body the one added last wins; :meth:`active` returns only that one per body.

    Times are compared in integer nanoseconds, as ros::Time does. A body is a scoped name "model::link";
    :meth:`clear` matches it exactly, as upstream matches ``GetScopedName()``.
    """

    def __init__(self):
        self._jobs = []  # [body, force, torque, point, start_ns, end_ns or None (forever)]

    def __len__(self):
        return len(self._jobs)

    def add(self, body, force, torque, reference_point, start_time, duration, now):
        """Schedule a wrench. ``now``: the sim time already reached (the time a service call reads)."""
        for what, value in (("start_time", start_time), ("duration", duration), ("now", now)):
            if not math.isfinite(float(value)):
                raise ValueError(f"apply_body_wrench: {what} is {float(value)!r}")
        start = max(_ns(start_time), _ns(now))
        end = None if float(duration) < 0.0 else start + _ns(duration)
        point = None if reference_point is None else floats(reference_point)
        self._jobs.append([body, floats(force), floats(torque), point, start, end])

    def active(self, now):
        """[(body, force, torque, point)] to apply during the coming step, at most one per body (the last
        added); jobs past their end are dropped. ``now``: the sim time this step will REACH (current sim
        time + step), which is what Gazebo's slot reads."""
        t = _ns(now)
        out, keep = {}, []
        for job in self._jobs:
            body, force, torque, point, start, end = job
            if t >= start and (end is None or t <= end):
                out[body] = (body, force, torque, point)
            if end is None or t <= end:
                keep.append(job)
        self._jobs = keep
        return list(out.values())

    def clear(self, body):
        """Drop every job on ``body`` (clear_body_wrenches); returns how many."""
        before = len(self._jobs)
        self._jobs = [job for job in self._jobs if job[0] != body]
        return before - len(self._jobs)

    def clear_model(self, model):
        """Drop every job on a link of ``model`` or of a model nested in it (delete_model); returns how
        many."""
        prefix = model + "::"
        before = len(self._jobs)
        self._jobs = [job for job in self._jobs if not job[0].startswith(prefix)]
        return before - len(self._jobs)

    def clear_all(self):
        """Drop every job (reset_simulation/reset_world keep them upstream; this is for shutting down)."""
        count, self._jobs = len(self._jobs), []
        return count


class JointEffortSchedule:
    """apply_joint_effort / clear_joint_forces jobs, timed as gazebo_ros's ``jointEffortSchedulerSlot``.

    A job: (joint, effort) from ``start`` for ``duration``; a start before now means now. Each step (at the
    time it will reach, as :class:`WrenchSchedule`) a job applies when ``t >= start`` and (``duration < 0`` or
    ``t <= start + duration``) and goes once ``t > start + duration``. Unlike body wrenches, joint efforts add
    up (Gazebo's ODE joints sum SetForce calls within a step): :meth:`active` gives every active job. The
    srv file's "duration 0: do nothing" and "shorter than a step: one step with a warning" are not what
    upstream does, and not done here.
    """

    def __init__(self):
        self._jobs = []  # [joint, effort, start_ns, end_ns or None]

    def __len__(self):
        return len(self._jobs)

    def add(self, joint, effort, start_time, duration, now):
        for what, value in (("effort", effort), ("start_time", start_time), ("duration", duration)):
            if not math.isfinite(float(value)):
                raise ValueError(f"ApplyJointEffort: {what} is {float(value)!r}")
        start = max(_ns(start_time), _ns(now))
        end = None if float(duration) < 0.0 else start + _ns(duration)
        self._jobs.append([joint, float(effort), start, end])

    def active(self, now):
        """[(joint, effort)] to apply during the step that reaches ``now``; ended jobs are dropped."""
        t = _ns(now)
        out, keep = [], []
        for job in self._jobs:
            joint, effort, start, end = job
            if t >= start and (end is None or t <= end):
                out.append((joint, effort))
            if end is None or t <= end:
                keep.append(job)
        self._jobs = keep
        return out

    def clear(self, joint):
        """Drop every job on ``joint`` (clear_joint_forces); returns how many."""
        before = len(self._jobs)
        self._jobs = [job for job in self._jobs if job[0] != joint]
        return before - len(self._jobs)

    def clear_all(self):
        count, self._jobs = len(self._jobs), []
        return count


# ------------------------------------------------------------------------------------------ physics

#: PyBullet's default numSolverIterations (the installed client reports 50).
PYBULLET_SOLVER_ITERATIONS = 50


def physics_properties(time_step, real_time_factor, real_time, paused, gravity_z,
                       solver_iterations=PYBULLET_SOLVER_ITERATIONS):
    """GetPhysicsProperties' response fields, with an ``ode_config`` that says what PyBullet does.

    ``max_update_rate`` is Gazebo's real_time_update_rate: steps per wall second when paced
    (``real_time_factor / time_step``: 1000 for 1 ms steps at real time), 0 for "as fast as possible"
    (``real_time`` false). ``gravity``: (0, 0, gravity_z): only vertical gravity is simulated.

    ``ode_config`` (gazebo_msgs/ODEPhysics field names), Bullet's equivalent of each ODE quickstep setting:

    * auto_disable_bodies False: bodies never sleep (PyBullet only lets them with URDF_ENABLE_SLEEPING).
    * sor_pgs_precon_iters 0: Bullet's solver has no preconditioning pass (Gazebo's default is 0 too).
    * sor_pgs_iters ``solver_iterations``: PyBullet's numSolverIterations (sequential impulse, PGS-like).
    * sor_pgs_w 1.0: Bullet's SOR factor (btContactSolverInfo m_sor), no over-relaxation (Gazebo's 1.3).
    * sor_pgs_rms_error_tol 0.0: upstream never fills this field (always 0 from Gazebo); left so.
    * contact_surface_layer 1e-5 m: PyBullet's contactSlop (m_linearSlop), the penetration allowed before
      correction, which is what ODE's surface layer is (Gazebo's default 0.001).
    * contact_max_correcting_vel inf: Bullet does not cap the penetration-correcting velocity.
    * cfm 0.0: Bullet's global CFM (m_globalCfm).
    * erp 0.2: Bullet's ERP for contacts shallower than its split-impulse threshold (m_erp; deeper ones
      use split impulse with erp2 0.08), same as Gazebo's default.
    * max_contacts 4: Bullet keeps at most 4 contact points per body pair (its manifold size; Gazebo 20).
    """
    rate = real_time_factor / time_step if real_time else 0.0
    return {
        "time_step": float(time_step),
        "pause": bool(paused),
        "max_update_rate": float(rate),
        "gravity": (0.0, 0.0, float(gravity_z)),
        "ode_config": {
            "auto_disable_bodies": False,
            "sor_pgs_precon_iters": 0,
            "sor_pgs_iters": int(solver_iterations),
            "sor_pgs_w": 1.0,
            "sor_pgs_rms_error_tol": 0.0,
            "contact_surface_layer": 1e-5,
            "contact_max_correcting_vel": math.inf,
            "cfm": 0.0,
            "erp": 0.2,
            "max_contacts": 4,
        },
    }
