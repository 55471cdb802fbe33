"""gazebo_ros_control's controller manager (plugins/ros_control/manager) without a ROS master: load, switch and
unload as controller_manager rules them, the update schedule of running controllers, autostart, and the
controller_manager services' handlers called with their request objects. The arms are the fixture arms in
PyBullet with their YAML as the parameter server; what a controller makes the arm do is judged by the body."""
import pytest
from conftest import DT, parameter_server
from controller_manager_msgs import srv as cm_srv
from std_msgs.msg import Float64, Float64MultiArray

from diffbot_sim.control.controller_switching import BEST_EFFORT, STRICT, SwitchError
from diffbot_sim.errors import ModelError
from diffbot_sim.plugins.ros_control import hardware, manager
from diffbot_sim.plugins.ros_control.controller import Controller

GROUP = {"type": "position_controllers/JointGroupPositionController", "joints": ["joint_1", "joint_2", "joint_3"]}
SHOULDER = {"type": "position_controllers/JointPositionController", "joint": "joint_2"}
JSC = {"type": "joint_state_controller/JointStateController", "publish_rate": 50}
PID = {"type": "effort_controllers/JointPositionController", "joint": "joint_1", "pid": {"p": 5.0, "d": 0.1}}


@pytest.fixture
def rig(arm_rig, monkeypatch):
    """``rig(name, params, period=None)`` -> (arm rig, hardware, manager in namespace ``/``); the parameter
    server holds ``params`` only (the fixtures' YAML has trajectory controllers, whose action servers need a
    master)."""
    def make(name, params, period=None):
        arm = arm_rig(name, params, use_yaml=False)
        get_param = parameter_server(arm.params)
        monkeypatch.setattr(hardware, "get_param", get_param)
        monkeypatch.setattr(manager, "get_param", get_param)
        hw = hardware.RobotHWSim(arm.ctx, "/", arm.ctx.warnings)
        hw.start()
        return arm, hw, manager.ControllerManager(arm.ctx, hw, "/", period)
    return make


def run(arm, hw, cm, seconds):
    """The loop, as the plugin drives it: writeSim before each physics step, the controllers after it."""
    for _ in range(max(1, round(seconds / DT))):
        hw.write(DT)
        arm.world.step()
        arm.sim.sim_time += DT
        cm.update(arm.sim.sim_time, None, [])


# -- load, switch, unload -------------------------------------------------------------------------------------

def test_load_builds_a_stopped_controller_from_its_parameters(rig):
    arm, hw, cm = rig("arm_position_nogains", {"arm_controller": GROUP})
    controller = cm.load("arm_controller")
    assert cm.loaded == {"arm_controller": controller} and cm.running == []
    assert controller.joints() == {"joint_1", "joint_2", "joint_3"}
    assert "/arm_controller/command" in arm.ctx.endpoints  # under the manager's namespace


@pytest.mark.parametrize("name, params, message", [
    ("nothing", {}, "Could not load controller 'nothing' because the type was not specified"),
    ("odd", {"odd": {"type": "my_pkg/MyController"}},
     "Could not load controller 'odd' because controller type 'my_pkg/MyController' does not exist here"),
])
def test_load_refuses_as_controller_manager_does(rig, name, params, message):
    _, _, cm = rig("arm_position_nogains", params)
    with pytest.raises(SwitchError, match=message):
        cm.load(name)
    assert cm.loaded == {}


def test_a_name_loads_once(rig):
    _, _, cm = rig("arm_position_nogains", {"arm_controller": GROUP})
    cm.load("arm_controller")
    with pytest.raises(SwitchError, match="A controller named 'arm_controller' was already loaded"):
        cm.load("arm_controller")


def test_a_started_group_controller_moves_the_arm_where_it_is_told(rig):
    arm, hw, cm = rig("arm_position_nogains", {"arm_controller": GROUP})
    cm.load("arm_controller")
    cm.switch(["arm_controller"], [], STRICT)
    arm.ctx.endpoints["/arm_controller/command"].callback(Float64MultiArray(data=[0.3, 0.2, -0.1]))
    run(arm, hw, cm, 1.0)
    assert [arm.joint(j)[0] for j in ("joint_1", "joint_2", "joint_3")] == pytest.approx([0.3, 0.2, -0.1],
                                                                                          abs=1e-5)


def test_two_running_controllers_may_not_claim_one_joint(rig):
    arm, hw, cm = rig("arm_position_nogains", {"arm_controller": GROUP, "shoulder": SHOULDER})
    cm.load("arm_controller")
    cm.load("shoulder")
    cm.switch(["arm_controller"], [], STRICT)
    for strictness in (STRICT, BEST_EFFORT):
        with pytest.raises(SwitchError, match="Resource conflict: controllers 'arm_controller' and 'shoulder' "
                                              "both claim joint 'joint_2'"):
            cm.switch(["shoulder"], [], strictness)
    assert [c.name for c in cm.running] == ["/arm_controller"]
    cm.switch(["shoulder"], ["arm_controller"], STRICT)  # one request: stop, then start
    assert [c.name for c in cm.running] == ["/shoulder"]


def test_best_effort_skips_unknown_names_and_strict_refuses_them(rig):
    _, _, cm = rig("arm_position_nogains", {"arm_controller": GROUP})
    cm.load("arm_controller")
    with pytest.raises(SwitchError, match="Could not start controller with name 'ghost'"):
        cm.switch(["arm_controller", "ghost"], [], STRICT)
    assert cm.running == []
    cm.switch(["arm_controller", "ghost"], [], BEST_EFFORT)
    assert [c.name for c in cm.running] == ["/arm_controller"]


class Refuses(Controller):
    """A controller whose start fails (upstream's controller_manager would crash there)."""

    type = "test/Refuses"

    def joints(self):
        return {"joint_2"}

    def start(self, now):
        raise ModelError("refuses to start")


def test_a_controller_that_cannot_start_undoes_the_switch(rig, monkeypatch):
    monkeypatch.setitem(manager.FACTORIES, Refuses.type, lambda ctx, hw, name, params, ns: Refuses(ctx, hw, name,
                                                                                                   params))
    monkeypatch.setattr(manager, "KNOWN_TYPES", frozenset(manager.FACTORIES))
    arm, hw, cm = rig("arm_position_nogains", {"arm_controller": GROUP, "bad": {"type": Refuses.type}})
    cm.load("arm_controller")
    cm.load("bad")
    cm.switch(["arm_controller"], [], STRICT)
    arm.ctx.endpoints["/arm_controller/command"].callback(Float64MultiArray(data=[0.0, 0.4, 0.0]))
    run(arm, hw, cm, 0.5)
    with pytest.raises(ModelError, match="refuses to start"):
        cm.switch(["bad"], ["arm_controller"], STRICT)
    assert [c.name for c in cm.running] == ["/arm_controller"]  # running again: the arm is never left unheld
    run(arm, hw, cm, 0.5)
    assert arm.joint("joint_2")[0] == pytest.approx(0.4, abs=1e-3)


def test_only_a_stopped_controller_unloads_and_its_endpoints_go_with_it(rig):
    arm, _, cm = rig("arm_position_nogains", {"arm_controller": GROUP})
    cm.load("arm_controller")
    cm.switch(["arm_controller"], [], STRICT)
    with pytest.raises(SwitchError, match="because it is still running"):
        cm.unload("arm_controller")
    cm.switch([], ["arm_controller"], STRICT)
    cm.unload("arm_controller")
    assert cm.loaded == {} and arm.ctx.released == ["/arm_controller/command"]
    assert arm.ctx.endpoints["/arm_controller/command"].closed


def test_states_list_what_each_controller_claims(rig):
    _, _, cm = rig("arm_position_nogains", {"arm_controller": GROUP, "joint_state_controller": JSC})
    cm.load("joint_state_controller")
    cm.load("arm_controller")
    cm.switch(["joint_state_controller"], [], STRICT)
    assert cm.states() == [
        ("joint_state_controller", "running", JSC["type"], {"JointStateInterface": []}),
        ("arm_controller", "stopped", GROUP["type"], {"PositionJointInterface": ["joint_1", "joint_2", "joint_3"]}),
    ]


def joint_state_names(arm_rig, monkeypatch, plugin_topic, autostart):
    """The joint names joint_state_controller publishes on /joint_states for arm_position_nogains with joint_3 left
    without its transmission (a passive joint), while a joint state publisher plugin publishes joint_3 on
    ``plugin_topic``; made before that plugin (``autostart``: the ros_control plugin's autostart runs while the
    robot's plugins are being created, the joint state publisher last) or after it (a spawner)."""
    from diffbot_sim.config import JointStateConfig
    from diffbot_sim.plugins.joint_state import JointStatePublisher

    arm = arm_rig("arm_position_nogains", {"joint_state_controller": JSC}, use_yaml=False)
    arm.model.transmissions = [t for t in arm.model.transmissions if t.joint != "joint_3"]
    get_param = parameter_server(arm.params)
    monkeypatch.setattr(hardware, "get_param", get_param)
    monkeypatch.setattr(manager, "get_param", get_param)
    hw = hardware.RobotHWSim(arm.ctx, "/", arm.ctx.warnings)
    hw.start()
    cm = manager.ControllerManager(arm.ctx, hw, "/", None)

    def plugin():
        JointStatePublisher(arm.ctx, JointStateConfig(joints=["joint_3"]), topic=plugin_topic)
    if not autostart:
        plugin()
    controller = cm.load("joint_state_controller")
    cm.switch(["joint_state_controller"], [], STRICT)
    if autostart:
        plugin()
    run(arm, hw, cm, 0.05)
    assert controller.pub.name == "/joint_states"
    published = controller.pub.published
    assert published, "joint_state_controller published nothing"
    return {tuple(msg.name) for msg in published}


@pytest.mark.parametrize("autostart", [False, True])
def test_joint_state_controller_leaves_out_a_passive_joint_a_plugin_publishes_on_its_topic(arm_rig, monkeypatch,
                                                                                          autostart):
    """Gazebo's joint_state_controller publishes only the hardware joints; ours adds the model's other movable
    joints for TF, but not one a plugin already puts on the same topic: two messages of one step carrying a joint
    are, to MoveIt's CurrentStateMonitor, a state 'not newer than the previous', and it then forgets every
    joint's time (the arm's state incomplete, plans and executions refused)."""
    assert joint_state_names(arm_rig, monkeypatch, "/joint_states", autostart) == {("joint_1", "joint_2")}


def test_joint_state_controller_adds_a_passive_joint_published_only_on_another_topic(arm_rig, monkeypatch):
    assert joint_state_names(arm_rig, monkeypatch, "/other/joint_states", True) == {("joint_1", "joint_2", "joint_3")}


# -- the update schedule ------------------------------------------------------------------------------------

def count_updates(controller):
    calls = []
    update = controller.update

    def counted(now, period, stamp, transforms):
        calls.append((round(now, 9), round(period, 9)))
        update(now, period, stamp, transforms)
    controller.update = counted
    return calls


def test_without_a_control_period_closed_loops_run_every_step_and_the_others_every_10_ms(rig):
    arm, hw, cm = rig("arm_effort_jtc", {"pid": PID, "forward": {
        "type": "effort_controllers/JointEffortController", "joint": "joint_2"}})
    pid, forward = cm.load("pid"), cm.load("forward")
    cm.switch(["pid", "forward"], [], STRICT)
    assert pid.closed_loop and not forward.closed_loop and cm.step_due()
    pid_calls, forward_calls = count_updates(pid), count_updates(forward)
    run(arm, hw, cm, 0.1)
    steps = round(0.1 / DT)
    assert len(pid_calls) == steps and all(period == round(DT, 9) for _, period in pid_calls)
    # the first at the first step, then one per 10 ms slot: 11 in (0, 0.1 s]
    assert len(forward_calls) == 11 and all(period == pytest.approx(manager.CONTROL_PERIOD, abs=DT)
                                            for _, period in forward_calls[1:])


def test_a_control_period_paces_every_controller(rig):
    arm, hw, cm = rig("arm_effort_jtc", {"pid": PID}, period=0.05)
    pid = cm.load("pid")
    cm.switch(["pid"], [], STRICT)
    calls = count_updates(pid)
    run(arm, hw, cm, 0.5)
    assert not cm.step_due() and len(calls) == 11  # the first step, then one per 50 ms slot
    assert all(period == pytest.approx(0.05, abs=1e-9) for _, period in calls[2:])  # 12 steps of 1/240 s


def test_a_pid_controller_holds_its_joint_at_the_command(rig):
    arm, hw, cm = rig("arm_effort_jtc", {"pid": PID})
    cm.load("pid")
    cm.switch(["pid"], [], STRICT)
    arm.ctx.endpoints["/pid/command"].callback(Float64(data=0.5))
    run(arm, hw, cm, 3.0)
    assert arm.joint("joint_1")[0] == pytest.approx(0.5, abs=0.01)


# -- autostart --------------------------------------------------------------------------------------------

def test_autostart_starts_every_simulated_controller_and_names_the_others(rig):
    arm, _, cm = rig("arm_position_nogains", {"arm_controller": GROUP, "joint_state_controller": JSC,
                                              "odd": {"type": "my_pkg/MyController", "joints": ["joint_1"]}})
    cm.autostart("/robot/gazebo[1]/plugin[@name='gazebo_ros_control']")
    assert sorted(c.name for c in cm.running) == ["/arm_controller", "/joint_state_controller"]
    assert "/odd: controller type my_pkg/MyController is not simulated" in arm.ctx.warnings


def test_autostart_of_conflicting_controllers_is_a_model_error(rig):
    _, _, cm = rig("arm_position_nogains", {"arm_controller": GROUP, "shoulder": SHOULDER})
    with pytest.raises(ModelError, match="Resource conflict"):
        cm.autostart("plugin")


def test_autostart_with_nothing_to_start_says_where_it_looked(rig):
    arm, _, cm = rig("arm_position_nogains", {})
    cm.autostart("plugin")
    assert cm.running == [] and any("no controller found on the parameter server under /" in w
                                    for w in arm.ctx.warnings)


# -- the controller_manager services ------------------------------------------------------------------------

@pytest.fixture
def services(rig):
    arm, hw, cm = rig("arm_position_nogains", {"arm_controller": GROUP, "joint_state_controller": JSC})
    served = manager.ControllerManagerServices(arm.ctx, cm)
    handlers = {name.rsplit("/", 1)[1]: endpoint.callback for name, endpoint in arm.ctx.endpoints.items()
                if endpoint.kind == "service"}
    return arm, cm, served, handlers


def test_the_services_are_controller_managers_under_the_namespace(services):
    arm, _, _, handlers = services
    assert sorted(n for n, e in arm.ctx.endpoints.items() if e.kind == "service") == [
        f"/controller_manager/{name}" for name in ("list_controller_types", "list_controllers", "load_controller",
                                                   "reload_controller_libraries", "switch_controller",
                                                   "unload_controller")]


def test_load_switch_list_and_unload_through_the_services(services):
    _, cm, _, call = services
    assert call["load_controller"](cm_srv.LoadControllerRequest(name="arm_controller")).ok
    assert not call["load_controller"](cm_srv.LoadControllerRequest(name="arm_controller")).ok  # already loaded
    assert not call["load_controller"](cm_srv.LoadControllerRequest(name="nothing")).ok
    assert call["switch_controller"](cm_srv.SwitchControllerRequest(
        start_controllers=["arm_controller"], stop_controllers=[], strictness=STRICT)).ok
    (state,) = call["list_controllers"](cm_srv.ListControllersRequest()).controller
    assert (state.name, state.state, state.type) == ("arm_controller", "running", GROUP["type"])
    assert [(r.hardware_interface, r.resources) for r in state.claimed_resources] == [
        ("hardware_interface::PositionJointInterface", ["joint_1", "joint_2", "joint_3"])]
    assert not call["unload_controller"](cm_srv.UnloadControllerRequest(name="arm_controller")).ok  # running
    assert call["switch_controller"](cm_srv.SwitchControllerRequest(
        start_controllers=[], stop_controllers=["arm_controller"], strictness=STRICT)).ok
    assert call["unload_controller"](cm_srv.UnloadControllerRequest(name="arm_controller")).ok
    assert cm.loaded == {}


def test_list_controller_types_names_every_simulated_type(services):
    _, _, _, call = services
    answer = call["list_controller_types"](cm_srv.ListControllerTypesRequest())
    assert answer.types == sorted(manager.KNOWN_TYPES) and GROUP["type"] in answer.types
    assert set(answer.base_classes) == {"controller_interface::ControllerBase"}


def test_reload_libraries_needs_force_kill_while_controllers_are_loaded(services):
    _, cm, _, call = services
    cm.load("arm_controller")
    cm.load("joint_state_controller")
    cm.switch(["arm_controller"], [], STRICT)
    assert not call["reload_controller_libraries"](cm_srv.ReloadControllerLibrariesRequest(force_kill=False)).ok
    assert len(cm.loaded) == 2
    assert call["reload_controller_libraries"](cm_srv.ReloadControllerLibrariesRequest(force_kill=True)).ok
    assert cm.loaded == {} and cm.running == []


def test_a_switch_asked_while_paused_waits_for_the_first_step_and_starts_from_the_pose_set_meanwhile(services):
    """A Gazebo launch spawns paused, ``spawn_model -J`` sets the arm's pose, the spawner switches its controllers
    on and the world is unpaused. Upstream's switch service waits for the realtime loop's next update, so the
    controller starts holding the -J pose. Here the switch waits likewise (it used to run at once while paused,
    so the controller held the pose before -J and pulled the arm back to it)."""
    import threading

    arm, cm, _, call = services
    assert call["load_controller"](cm_srv.LoadControllerRequest(name="arm_controller")).ok
    arm.sim.paused = True
    answers = []
    switch = threading.Thread(target=lambda: answers.append(call["switch_controller"](
        cm_srv.SwitchControllerRequest(start_controllers=["arm_controller"], strictness=STRICT))))
    switch.start()
    switch.join(0.3)
    assert switch.is_alive() and cm.pending  # waits while paused
    (state,) = call["list_controllers"](cm_srv.ListControllersRequest()).controller
    assert state.state != "running"
    pose = [0.4, -0.3, 0.5]
    arm.robot.set_joint_positions(arm.robot.indices(GROUP["joints"]), pose)  # -J, while paused
    arm.sim.paused = False
    cm.run_pending(arm.sim.sim_time)  # the plugin's before_step at the first step after the unpause
    switch.join(2.0)
    assert answers and answers[0].ok
    run(arm, cm.hw, cm, 0.5)
    for joint, want in zip(GROUP["joints"], pose):
        assert arm.joint(joint)[0] == pytest.approx(want, abs=1e-3)  # held where -J put it
