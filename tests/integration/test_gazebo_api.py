#!/usr/bin/env python3
"""The /gazebo world API through gazebo_msgs' own types, as user scripts (tests, RL resets, mission scripts)
call it: spawn a robot at run time that then drives, teleport it and drive from there, delete it while it
drives (its topics go), world models, link states, wrenches, physics properties, both resets, and bad
requests answered with success false and a reason while the simulator runs on.

The simulator starts as empty_world.launch starts it (node ``gazebo``, no robot) in tests/data/worlds/walls.world
(its models: box_wall, pillar, ring, moved_by_state, push_box (dynamic, a 0.3 kg 0.3 m cube at (1.15, 15, 0.15)),
fixed_box, platform, ground_plane). The robot is tests/data/robots/fixed_caster.urdf (ROS 1 diff drive:
cmd_vel, odom in its plugin's robotNamespace).
"""
import math
import os
import sys
import unittest

import rosgraph
import rospy
import rostest
from gazebo_msgs import msg as gmsg, srv as gsrv
from geometry_msgs.msg import Point, Pose, Quaternion, Twist, Vector3, Wrench
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from simtest import Latest, assert_upright, wait_for as wait, yaw_of
from std_srvs.srv import Empty

GZ = "/gazebo"
ROBOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "robots", "fixed_caster.urdf")
DRIVE = 0.6  # m a robot is driven (0.3 m/s for 2 s of sim time)
DRIVE_TIMEOUT = 60.0  # s wall: 2 s of sim time at 2x real time, on a 4x slower machine


def proxy(name, kind):
    rospy.wait_for_service(f"{GZ}/{name}", 30.0)
    return rospy.ServiceProxy(f"{GZ}/{name}", kind)


def pose(x=0.0, y=0.0, z=0.0, yaw=0.0):
    return Pose(Point(x, y, z), Quaternion(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))


def publishers_of(topic):
    """Nodes the master lists as publishing ``topic``."""
    state = rosgraph.Master("/test_gazebo_api").getSystemState()
    return next((nodes for name, nodes in state[0] if name == topic), [])


class GazeboApiTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_gazebo_api")
        with open(ROBOT) as f:
            cls.urdf = f.read()
        cls.spawn = proxy("spawn_urdf_model", gsrv.SpawnModel)
        cls.spawn_sdf = proxy("spawn_sdf_model", gsrv.SpawnModel)
        cls.delete = proxy("delete_model", gsrv.DeleteModel)
        cls.get_state = proxy("get_model_state", gsrv.GetModelState)
        cls.set_state = proxy("set_model_state", gsrv.SetModelState)
        cls.world = proxy("get_world_properties", gsrv.GetWorldProperties)
        cls.props = proxy("get_model_properties", gsrv.GetModelProperties)

    def spawn_robot(self, name, ns, x, y, yaw):
        resp = self.spawn(name, self.urdf, ns, pose(x, y, 0.0, yaw), "world")
        self.assertTrue(resp.success, resp.status_message)
        return resp

    def drive(self, ns, model, linear, distance):
        """Publish a command on ``ns``/cmd_vel until the body of ``model`` has moved ``distance`` m (its
        /gazebo/get_model_state), then a zero one. Judged by what the body did, not by a time: on a loaded
        machine the commands reach the simulator late, and a fixed time moves it less."""
        pub = rospy.Publisher(f"{ns}/cmd_vel", Twist, queue_size=1)
        wait(lambda: pub.get_num_connections() > 0, 10.0, f"{ns}/cmd_vel subscriber")
        start = self.model(model).pose.position
        cmd = Twist()
        cmd.linear.x = linear

        def moved():
            pub.publish(cmd)
            p = self.model(model).pose.position
            return math.hypot(p.x - start.x, p.y - start.y) >= distance
        try:
            wait(moved, DRIVE_TIMEOUT, f"{model} to drive {distance} m on {ns}/cmd_vel", poll=0.05)
        finally:
            pub.publish(Twist())
        return pub

    def model(self, name, frame=""):
        resp = self.get_state(name, frame)
        self.assertTrue(resp.success, resp.status_message)
        return resp

    # -- tests ---------------------------------------------------------------------------------------
    def test_01_world_properties_list_the_world_models(self):
        resp = self.world()
        self.assertTrue(resp.success)
        for name in ("ground_plane", "box_wall", "push_box", "platform"):
            self.assertIn(name, resp.model_names)
        # the services answer from the start; sim time runs from the loop's first step (once 0.0 here)
        wait(lambda: self.world().sim_time > 0.0, 10.0, "sim time running")
        box = self.model("push_box")
        self.assertAlmostEqual(box.pose.position.x, 1.15, delta=0.02)
        self.assertAlmostEqual(box.pose.position.y, 15.0, delta=0.02)
        props = self.props("box_wall")
        self.assertTrue(props.success and props.is_static, props)

    def test_02_spawn_at_run_time_then_drive(self):
        """A robot spawned at (2, -3) facing +y with robot_namespace /bot1 publishes /bot1/odom and drives
        along +y when told to go forward."""
        self.spawn_robot("bot1", "/bot1", 2.0, -3.0, math.pi / 2)
        odom = Latest("/bot1/odom", Odometry)
        wait(odom.get, 10.0, "/bot1/odom after the spawn")
        start = self.model("bot1")
        self.assertAlmostEqual(start.pose.position.x, 2.0, delta=0.02)
        self.assertAlmostEqual(start.pose.position.y, -3.0, delta=0.02)
        self.assertAlmostEqual(yaw_of(start.pose.orientation), math.pi / 2, delta=0.02)
        self.drive("/bot1", "bot1", 0.3, DRIVE)
        end = self.model("bot1")
        assert_upright(end.pose, 0.0, "bot1 after the drive")
        self.assertGreater(end.pose.position.y - start.pose.position.y, 0.3)
        self.assertLess(abs(end.pose.position.x - start.pose.position.x), 0.1)
        self.assertIn("bot1", self.world().model_names)
        props = self.props("bot1")
        self.assertEqual(props.canonical_body_name, "base_footprint")
        self.assertEqual(sorted(props.body_names), ["base_footprint", "left_wheel_link", "right_wheel_link"])
        self.assertIn("left_wheel_joint", props.joint_names)
        self.assertFalse(props.is_static)

    def test_03_spawn_refusals_keep_the_simulator_running(self):
        self.spawn_robot("bot_dup", "/bot_dup", -3.0, -3.0, 0.0)
        cases = [
            (gsrv.SpawnModelRequest("bot_dup", self.urdf, "/x", pose(-5, -5), ""), "already exists"),
            (gsrv.SpawnModelRequest("bad_xml", "<robot name='x'><link name='a'>", "", pose(-6, -6), ""), "xml"),
            (gsrv.SpawnModelRequest("nan_pose", self.urdf, "/n", pose(float("nan"), 0), ""), "nan"),
            (gsrv.SpawnModelRequest("no_frame", self.urdf, "/f", pose(-7, -7), "no_such_model"), "no_such_model"),
            (gsrv.SpawnModelRequest("pkg", self.urdf.replace("<robot", "<robot><link name='m'><visual><geometry>"
                                    "<mesh filename='package://no_such_pkg_xyz/m.stl'/></geometry></visual></link"
                                    "><!--", 1).replace("</robot>", "--></robot>"), "", pose(-8, -8), ""),
             "no_such_pkg_xyz"),
        ]
        for request, needle in cases:
            resp = self.spawn(request)
            self.assertFalse(resp.success, request.model_name)
            self.assertIn(needle.lower(), resp.status_message.lower(), resp.status_message)
        for name in ("bad_xml", "nan_pose", "no_frame", "pkg"):
            self.assertNotIn(name, self.world().model_names)
        missing = self.get_state("no_such_model", "")
        self.assertFalse(missing.success)
        self.assertIn("does not exist", missing.status_message)
        before = self.world().sim_time
        wait(lambda: self.world().sim_time > before + 0.2, 10.0, "sim time going on after refusals")

    def test_04_set_model_state_teleports_then_drives_from_there(self):
        self.spawn_robot("bot_tp", "/bot_tp", -2.0, 3.0, 0.0)
        odom = Latest("/bot_tp/odom", Odometry)
        wait(odom.get, 10.0, "/bot_tp/odom")
        state = gmsg.ModelState("bot_tp", pose(4.0, -6.0, 0.0, math.pi), Twist(), "world")
        resp = self.set_state(state)
        self.assertTrue(resp.success, resp.status_message)
        there = self.model("bot_tp")
        self.assertAlmostEqual(there.pose.position.x, 4.0, delta=0.03)
        self.assertAlmostEqual(there.pose.position.y, -6.0, delta=0.03)
        self.drive("/bot_tp", "bot_tp", 0.3, DRIVE)
        end = self.model("bot_tp")
        assert_upright(end.pose, 0.0, "bot_tp after the teleport and the drive")
        self.assertLess(end.pose.position.x, 4.0 - 0.3, "facing -x after the teleport, it drives towards -x")
        self.assertAlmostEqual(end.pose.position.y, -6.0, delta=0.1)
        # relative to another model: bot_tp seen from push_box (yaw 0)
        box = self.model("push_box").pose.position
        rel = self.model("bot_tp", "push_box")
        self.assertAlmostEqual(rel.pose.position.x, end.pose.position.x - box.x, delta=0.05)
        self.assertAlmostEqual(rel.pose.position.y, end.pose.position.y - box.y, delta=0.05)
        # the topic form, with a reference frame: 1 m ahead of push_box
        pub = rospy.Publisher(f"{GZ}/set_model_state", gmsg.ModelState, queue_size=1)
        wait(lambda: pub.get_num_connections() > 0, 10.0, "set_model_state topic subscriber")
        pub.publish(gmsg.ModelState("bot_tp", pose(-3.0, -2.0, 0.0), Twist(), "push_box"))
        wait(lambda: abs(self.model("bot_tp").pose.position.x - (box.x - 3.0)) < 0.05, 10.0,
             "bot_tp moved by the set_model_state topic relative to push_box")
        bad = self.set_state(gmsg.ModelState("bot_tp", pose(0, 0, float("inf")), Twist(), ""))
        self.assertFalse(bad.success)
        bad = self.set_state(gmsg.ModelState("nobody", pose(), Twist(), ""))
        self.assertFalse(bad.success)
        self.assertIn("nobody", bad.status_message)

    def test_05_delete_while_driving_removes_its_topics(self):
        self.spawn_robot("bot_del", "/bot_del", 5.0, 5.0, 0.0)
        odom = Latest("/bot_del/odom", Odometry)
        wait(odom.get, 10.0, "/bot_del/odom")
        self.assertTrue(publishers_of("/bot_del/odom"))
        pub = rospy.Publisher("/bot_del/cmd_vel", Twist, queue_size=1)
        wait(lambda: pub.get_num_connections() > 0, 10.0, "/bot_del/cmd_vel subscriber")
        cmd = Twist()
        cmd.linear.x = 0.3
        pub.publish(cmd)
        resp = self.delete("bot_del")
        self.assertTrue(resp.success, resp.status_message)
        self.assertNotIn("bot_del", self.world().model_names)
        wait(lambda: not publishers_of("/bot_del/odom"), 10.0, "/bot_del/odom unregistered")
        count = odom.count
        pub.publish(cmd)
        # observing that nothing arrives, for 0.5 s of the simulator's time (25 odom messages, were it still
        # publishing), not of this node's wall clock, which a busy machine can give it little of
        looked_from = self.world().sim_time
        wait(lambda: self.world().sim_time >= looked_from + 0.5, 10.0, "0.5 s of sim time after the delete")
        self.assertLessEqual(odom.count, count + 1)
        again = self.delete("bot_del")
        self.assertFalse(again.success)
        before = self.world().sim_time
        wait(lambda: self.world().sim_time > before + 0.2, 10.0, "sim time going on after the delete")
        # the name is free again
        self.spawn_robot("bot_del", "/bot_del", 5.0, 5.0, 0.0)
        self.assertTrue(self.delete("bot_del").success)

    def test_06_model_and_link_states_topics(self):
        self.spawn_robot("bot_ls", "/bot_ls", -4.0, 8.0, 0.0)
        states = Latest(f"{GZ}/model_states", gmsg.ModelStates)
        links = Latest(f"{GZ}/link_states", gmsg.LinkStates)
        msg = wait(lambda: (m := states.get()) is not None and "bot_ls" in m.name and m, 10.0, "model_states")
        i = msg.name.index("bot_ls")
        self.assertAlmostEqual(msg.pose[i].position.x, -4.0, delta=0.03)
        self.assertIn("push_box", msg.name)
        lmsg = wait(lambda: (m := links.get()) is not None and "bot_ls::base_footprint" in m.name and m, 10.0,
                    "link_states")
        self.assertIn("bot_ls::left_wheel_link", lmsg.name)
        get_link = proxy("get_link_state", gsrv.GetLinkState)
        resp = get_link("bot_ls::base_footprint", "world")
        self.assertTrue(resp.success, resp.status_message)
        self.assertAlmostEqual(resp.link_state.pose.position.x, -4.0, delta=0.03)
        set_link = proxy("set_link_state", gsrv.SetLinkState)
        resp = set_link(gmsg.LinkState("bot_ls::base_footprint", pose(-4.0, 9.0), Twist(), "world"))
        self.assertTrue(resp.success, resp.status_message)
        self.assertAlmostEqual(self.model("bot_ls").pose.position.y, 9.0, delta=0.03)
        self.assertFalse(get_link("bot_ls::no_link", "").success)
        self.assertFalse(get_link("nolinkname", "").success)
        states.sub.unregister()
        links.sub.unregister()
        self.delete("bot_ls")

    def test_07_wrench_pushes_a_dynamic_box(self):
        apply = proxy("apply_body_wrench", gsrv.ApplyBodyWrench)
        clear = proxy("clear_body_wrenches", gsrv.BodyRequest)
        start = self.model("push_box").pose.position.x
        wrench = Wrench(Vector3(0.0, 40.0, 0.0), Vector3())
        resp = apply("push_box::link", "world", Point(), wrench, rospy.Time(0), rospy.Duration(-1))
        self.assertTrue(resp.success, resp.status_message)
        wait(lambda: self.model("push_box").twist.linear.y > 0.05, 20.0, "push_box moving along +y")
        clear("push_box::link")
        self.assertAlmostEqual(self.model("push_box").pose.position.x, start, delta=0.1)
        bad = apply("push_box::nolink", "world", Point(), wrench, rospy.Time(0), rospy.Duration(1))
        self.assertFalse(bad.success)

    def test_08_physics_properties_pause_and_resets(self):
        physics = proxy("get_physics_properties", gsrv.GetPhysicsProperties)()
        self.assertTrue(physics.success)
        self.assertAlmostEqual(physics.time_step, 0.001, places=9)  # walls.world's <max_step_size>
        self.assertFalse(physics.pause)
        self.assertAlmostEqual(physics.gravity.z, -9.8, delta=0.02)
        set_physics = proxy("set_physics_properties", gsrv.SetPhysicsProperties)
        request = gsrv.SetPhysicsPropertiesRequest(time_step=physics.time_step, max_update_rate=physics.max_update_rate,
                                                    gravity=Vector3(0.0, 0.0, -5.0), ode_config=physics.ode_config)
        self.assertTrue(set_physics(request).success)
        self.assertAlmostEqual(proxy("get_physics_properties", gsrv.GetPhysicsProperties)().gravity.z, -5.0)
        # a new step at run time, as Gazebo takes one: sim time goes on from where it was, at the new step
        request.gravity, request.time_step = physics.gravity, 0.002
        t0 = self.world().sim_time
        self.assertTrue(set_physics(request).success)
        changed = proxy("get_physics_properties", gsrv.GetPhysicsProperties)()
        self.assertAlmostEqual(changed.time_step, 0.002, places=9)
        wait(lambda: self.world().sim_time > t0 + 0.2, 10.0, "sim time at the new step")
        now = self.world().sim_time  # still on the 1 ms grid it was on: 2 ms steps from there
        self.assertAlmostEqual(round(now / 0.001) * 0.001, now, places=6)
        request.time_step = 1.0  # beyond the bounds of ~time_step
        refused = set_physics(request)
        self.assertFalse(refused.success)
        self.assertIn("time_step", refused.status_message)
        request.time_step = physics.time_step
        self.assertTrue(set_physics(request).success)
        self.assertAlmostEqual(proxy("get_physics_properties", gsrv.GetPhysicsProperties)().time_step, 0.001, places=9)
        rospy.ServiceProxy(f"{GZ}/pause_physics", Empty)()
        self.assertTrue(proxy("get_physics_properties", gsrv.GetPhysicsProperties)().pause)
        t0 = self.world().sim_time
        clock = Latest("/clock", Clock)  # Gazebo keeps publishing /clock while paused (spawners wait for one)
        wait(lambda: clock.count >= 3, 10.0, "/clock while paused")
        self.assertAlmostEqual(clock.get().clock.to_sec(), t0, delta=1e-6)
        self.assertEqual(self.world().sim_time, t0)
        clock.sub.unregister()
        rospy.ServiceProxy(f"{GZ}/unpause_physics", Empty)()
        wait(lambda: self.world().sim_time > t0 + 0.1, 10.0, "sim time after unpause")
        # reset_world: models back to where they started; time goes on
        self.spawn_robot("bot_rs", "/bot_rs", 7.0, -7.0, 0.0)
        self.set_state(gmsg.ModelState("bot_rs", pose(7.0, -5.0), Twist(), ""))
        t1 = self.world().sim_time
        rospy.ServiceProxy(f"{GZ}/reset_world", Empty)()
        self.assertAlmostEqual(self.model("bot_rs").pose.position.y, -7.0, delta=0.03)
        self.assertGreaterEqual(self.world().sim_time, t1)
        # reset_simulation: also sim time back to 0
        rospy.ServiceProxy(f"{GZ}/reset_simulation", Empty)()
        self.assertLess(self.world().sim_time, t1)
        self.delete("bot_rs")

    def test_09_spawn_sdf_model(self):
        box = ('<?xml version="1.0"?><sdf version="1.6"><model name="anything"><link name="link">'
               '<inertial><mass>2</mass></inertial><collision name="c"><geometry><box><size>0.4 0.4 0.4</size>'
               '</box></geometry></collision></link></model></sdf>')
        resp = self.spawn_sdf("goal", box, "", pose(3.0, 12.0, 1.0), "world")
        self.assertTrue(resp.success, resp.status_message)
        self.assertIn("goal", self.world().model_names)
        wait(lambda: abs(self.model("goal").pose.position.z - 0.2) < 0.02, 10.0, "the box falling onto the ground")
        self.assertAlmostEqual(self.model("goal").pose.position.x, 3.0, delta=0.02)
        self.assertFalse(self.spawn_sdf("goal", box, "", pose(), "").success)
        self.assertTrue(self.delete("goal").success)
        self.assertNotIn("goal", self.world().model_names)

    def test_10_set_model_configuration(self):
        self.spawn_robot("bot_cfg", "/bot_cfg", 8.0, 8.0, 0.0)
        configure = proxy("set_model_configuration", gsrv.SetModelConfiguration)
        resp = configure("bot_cfg", "", ["left_wheel_joint"], [1.0])
        self.assertTrue(resp.success, resp.status_message)
        # As upstream: names the model does not move are ignored; lists of different lengths and unknown
        # models are refused with its messages.
        resp = configure("bot_cfg", "", ["no_joint"], [1.0])
        self.assertTrue(resp.success, resp.status_message)
        resp = configure("bot_cfg", "", ["left_wheel_joint"], [1.0, 2.0])
        self.assertFalse(resp.success)
        self.assertIn("different lengths", resp.status_message)
        resp = configure("no_such_model", "", [], [])
        self.assertEqual((resp.success, resp.status_message), (False, "SetModelConfiguration: model does not exist"))
        self.delete("bot_cfg")

    def test_11_a_model_with_nothing_to_collide_is_a_model(self):
        """TurtleBot3's learning environment spawns its goal marker as a static model with one visual and no
        collision, then waits for it in model_states and deletes it: in Gazebo it is a model like any other."""
        marker = ('<?xml version="1.0"?><sdf version="1.6"><model name="goal"><static>true</static>'
                  '<link name="goal"><visual name="v"><geometry><cylinder><radius>0.1</radius><length>0.05'
                  '</length></cylinder></geometry></visual></link></model></sdf>')
        states = []
        sub = rospy.Subscriber("/gazebo/model_states", gmsg.ModelStates, states.append, queue_size=1)
        try:
            resp = self.spawn_sdf("goal_marker", marker, "robotos_name_space", pose(0.6, 0.0, 0.0), "world")
            self.assertTrue(resp.success, resp.status_message)
            wait(lambda: states and "goal_marker" in states[-1].name, 10.0, "the marker in model_states")
            self.assertIn("goal_marker", self.world().model_names)
            self.assertAlmostEqual(self.model("goal_marker").pose.position.x, 0.6, delta=1e-6)
            moved = gmsg.ModelState(model_name="goal_marker", pose=pose(-1.0, 0.5, 0.0))
            self.assertTrue(proxy("set_model_state", gsrv.SetModelState)(moved).success)
            self.assertAlmostEqual(self.model("goal_marker").pose.position.y, 0.5, delta=1e-6)
            self.assertTrue(self.delete("goal_marker").success)
            wait(lambda: states and "goal_marker" not in states[-1].name, 10.0, "the marker gone from model_states")
            self.assertFalse(self.delete("goal_marker").success)
        finally:
            sub.unregister()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_gazebo_api", GazeboApiTest, sys.argv)
