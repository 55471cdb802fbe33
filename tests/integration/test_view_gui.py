#!/usr/bin/env python3
"""view_gui suite: PyBullet's own window (``sim.launch gui:=true``) under Xvfb, judged by its pixels.

The seed robot in worlds/room.world, real time. PyBullet's window opens at 1024 x 768 with its default
camera (xscreen.PYBULLET_CAMERA: target the origin, 5 m, yaw 50, pitch -35); world points are projected
with that camera (xscreen.pybullet_pixel; checked against getDebugVisualizerCamera) to say where the robot
must be drawn. Only the part of the 3-D view no panel covers is judged (xscreen.PYBULLET_SCENE_BOX).

- The world: the room's walls have no colour in the world file, so PyBullet draws them in its palette (red,
  yellow, green, blue): strongly coloured pixels of each hue (xscreen.saturated) must be there, many. Each
  of these four counts must fall short on the frame after ``/gazebo/delete_model walls`` (the ring, the
  pillar and the box share the walls' colours: the thresholds sit between the two).
- The robot: frame A with the robot at the origin, frame B with it teleported out of view
  (``/gazebo/set_model_state``), frame C with it at (1, 0). A - B and C - B must each be one compact patch
  of changed pixels, at least a robot's worth, centred within CENTRE_TOLERANCE px of where the camera
  projects the robot's body; A to C must go the way the camera maps +x (to the lower right). Two frames
  without the robot (B and a later one) differ by far fewer pixels than a robot: the check fails when no
  robot is drawn.
"""
import math
import os
import subprocess
import sys
import time

import numpy as np
import rospy
import rostest
import viewtest
from gazebo_msgs.msg import ModelState
from gazebo_msgs.srv import DeleteModel, GetModelState, GetWorldProperties, SetModelState

from diffbot_sim.view import xscreen
from diffbot_sim.waiting import wait_for

ROOM = os.path.join(viewtest.ROOT, "worlds", "room.world")
ROBOT = "diffbot"  # the seed robot's URDF name: its model name
ROBOT_Z = 0.076  # m: the seed robot's body centre above the ground (base_z of diffbot.urdf.xacro)
AWAY = (30.0, 30.0)  # m: far outside the default camera's view (projects ~8700 px to the right)
START_TIMEOUT = 60.0  # s wall: master, simulator, PyBullet's window under llvmpipe on a 4x slower machine
SETTLE_TIMEOUT = 60.0  # s wall: PyBullet, drawing a frame every few seconds on a starved machine, shows a change
CALL_TIMEOUT = 30.0  # s wall: a /gazebo service answers (the loop runs it between steps) on a starved machine
SETTLE_PERIOD = 0.5  # s wall between screenshots while waiting
STABLE_WALL = 1.5  # s wall: the window unchanged this long (two screenshots at least): PyBullet has drawn it
SETTLE_CHANGED = 20  # px: "unchanged" frames differ in at most this many pixels; a change drawn differs in more
#: Strong pixels of each hue the room must show. Measured on the window's uncovered 3-D view: with the walls
#: red 16690, yellow 14742, green 8839, blue 25878; after deleting them red 38 (the x axis), yellow 1757 (the
#: box), green 4215 (the ring), blue 5543 (the pillar, the robot); before the world loads red 137, yellow 0,
#: green 127, blue 239.
WALL_MIN = {"red": 5000, "yellow": 5000, "green": 6500, "blue": 12000}
ROBOT_MIN_PIXELS = 150  # px changed: the robot's body (0.2 m wide, ~0.13 m high) at 5 m is ~15 x 12 px, plus
#                         its wheels and shadow
ROBOT_MAX_PIXELS = 3000  # px changed: more is not the robot alone
PATCH_RADIUS = 40  # px around the patch's median: the robot and its shadow
CENTRE_TOLERANCE = 40.0  # px between the patch's centre and the projected body centre


class ViewGui(viewtest.PictureSuite):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_view_gui")
        if not cls.start_view("view_gui", viewtest.View(["gui:=true", f"world:={ROOM}"], "view_gui_launch",
                                                        launch="sim.launch")):
            return
        display = cls.view.xvfb.display
        cls.window = cls.view.wait(lambda: cls.find_window(display), START_TIMEOUT, "PyBullet's window")
        # The window opens before the simulator builds the world and the robot: wait for both.
        cls.view.wait(lambda: rospy.has_param("/bullet_sim/world_bodies"), START_TIMEOUT,
                      "the simulator to load the world (/bullet_sim/world_bodies)")
        cls.view.wait(lambda: cls.view.last_odom() is not None, START_TIMEOUT, "odometry")
        for name in ("set_model_state", "get_model_state", "get_world_properties", "delete_model"):
            cls.view.wait(lambda: cls.view.service_up(f"/gazebo/{name}"), START_TIMEOUT, f"/gazebo/{name}")
        cls.set_state = rospy.ServiceProxy("/gazebo/set_model_state", SetModelState)
        cls.get_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
        cls.world_properties = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)
        cls.delete_model = rospy.ServiceProxy("/gazebo/delete_model", DeleteModel)

    # ------------------------------------------------------------------------------------- helpers

    @staticmethod
    def find_window(display):
        """PyBullet's window, or None (also when xwininfo is too slow to answer: "not yet", not a failure)."""
        try:
            return xscreen.find_window(display, "Bullet Physics")
        except subprocess.TimeoutExpired:
            return None

    def crashed(self):
        """After something went missing (the window, a service): fail naming roslaunch's exit when it ends
        within 5 s (a required node died: roslaunch stops the rest), else return."""
        try:
            wait_for(lambda: self.view.proc.poll() is not None, 5.0, "roslaunch to end", 0.2, error=AssertionError)
        except AssertionError:
            return
        self.view.alive()

    def call(self, proxy, *args):
        self.view.alive()
        try:
            return viewtest.with_timeout(lambda: proxy(*args), CALL_TIMEOUT, proxy.resolved_name)
        except (rospy.ServiceException, AssertionError):
            self.crashed()
            raise

    def poll(self, proxy, *args):
        """``proxy(*args)`` inside a polled wait: the answer, or a sentence saying why there is none (a slow
        or refused call is "not yet"; roslaunch ending fails at once)."""
        self.view.alive()
        try:
            return viewtest.with_timeout(lambda: proxy(*args), CALL_TIMEOUT, proxy.resolved_name)
        except (rospy.ServiceException, AssertionError) as err:
            return f"{proxy.resolved_name} gave no answer: {err}"

    def wait_named(self, ready, timeout, what):
        """Poll ``ready()``, which returns a true value when done or a sentence saying what is missing; fail
        naming ``what`` and that sentence (after checking whether roslaunch ended) once ``timeout`` passes."""
        why = ["nothing polled yet"]

        def check():
            self.view.alive()
            value = ready()
            if isinstance(value, str):
                why[0] = value
                return None
            return value
        started = time.monotonic()
        try:
            value = wait_for(check, timeout, what, SETTLE_PERIOD, error=AssertionError)
        except AssertionError as err:
            self.crashed()
            raise AssertionError(f"{what}: {why[0]} ({err})") from None
        print(f"view_gui: {what}: {time.monotonic() - started:.1f} s", flush=True)
        return value

    def frame(self):
        """The window's pixels, or a sentence saying why there are none (the window missing or not at its
        default size, for which the camera projection does not hold; a screenshot that failed)."""
        window = self.find_window(self.view.xvfb.display)
        if window is None:
            return "PyBullet's window is not there"
        if (window.width, window.height) != xscreen.PYBULLET_WINDOW:
            return (f"PyBullet's window is {window.width}x{window.height}, not its default "
                    f"{xscreen.PYBULLET_WINDOW[0]}x{xscreen.PYBULLET_WINDOW[1]}: the camera projection does not hold")
        try:
            return xscreen.crop(self.view.screenshot(), window.box())
        except (AssertionError, subprocess.TimeoutExpired) as err:
            return f"no screenshot: {err}"

    def frame_or_why(self):
        """``(frame,)`` (a tuple: a wait tests the truth of what it gets), or why there is no frame."""
        frame = self.frame()
        return frame if isinstance(frame, str) else (frame,)

    def settled(self, what, before=None, drawn=None):
        """Wait until PyBullet's window shows the scene as it now is, at rest; return the window's pixels.

        Conditions, the one that never held named in the failure:
        - the window is there at its default size (missing is "not yet": PyBullet may be remapping it);
        - with ``before`` (the window before a change: a teleport, a deletion): the 3-D scene differs from it in
          more than SETTLE_CHANGED pixels, so PyBullet has drawn the change (on a starved machine it redraws
          seconds late, and screenshots of the old picture are equal to each other);
        - ``drawn(frame)``, when given, returns None (else a sentence saying what the frame lacks);
        - the window is the same, but for SETTLE_CHANGED pixels, in every screenshot over STABLE_WALL seconds.
        """
        history = []  # (wall time, frame) of the screenshots since the window last changed

        def ready():
            frame = self.frame()
            if isinstance(frame, str):
                history[:] = []
                return frame
            if before is not None:
                redrawn = int(xscreen.changed(self.scene(before), self.scene(frame)).sum())
                if redrawn <= SETTLE_CHANGED:
                    history[:] = []
                    return (f"the scene as before the change ({redrawn} pixels differ, more than {SETTLE_CHANGED} "
                            "wanted): PyBullet has not drawn it yet, or does not draw what changed")
            reason = drawn(frame) if drawn is not None else None
            if reason:
                history[:] = []
                return reason
            history.append((time.monotonic(), frame))
            moved = max((int(xscreen.changed(old, frame).sum()) for _, old in history[:-1]), default=0)
            if moved > SETTLE_CHANGED:
                history[:] = history[-1:]
                return (f"the window changed in {moved} pixels (more than {SETTLE_CHANGED}) between screenshots: "
                        "PyBullet still drawing, or something still moving")
            held = history[-1][0] - history[0][0]
            if len(history) < 2 or held < STABLE_WALL:
                return f"the window unchanged for {held:.1f} s of the {STABLE_WALL:g} s wanted"
            return (frame,)  # a tuple: the wait tests the truth of what it gets
        return self.wait_named(ready, SETTLE_TIMEOUT, what)[0]

    def scene(self, frame):
        return xscreen.crop(frame, xscreen.PYBULLET_SCENE_BOX)

    def walls_missing(self, frame):
        """None once the scene shows WALL_MIN strong pixels of every hue (the room is drawn), else what it shows:
        the window opens before the world is built, and on a starved machine is drawn seconds after that."""
        counts = xscreen.color_counts(self.scene(frame))
        if all(counts[hue] >= least for hue, least in WALL_MIN.items()):
            return None
        return f"the room's colours not drawn yet: {counts} (at least {WALL_MIN} wanted)"

    def teleport(self, x, y):
        """Put the robot at (x, y) on the ground (its height and heading kept), at rest; wait until it is."""
        now = self.call(self.get_state, ROBOT, "world")
        self.assertTrue(now.success, now.status_message)
        state = ModelState(model_name=ROBOT, reference_frame="world")
        state.pose = now.pose
        state.pose.position.x, state.pose.position.y = x, y
        answer = self.call(self.set_state, state)
        self.assertTrue(answer.success, answer.status_message)

        def there():
            answer = self.poll(self.get_state, ROBOT, "world")
            if isinstance(answer, str):
                return answer
            p = answer.pose.position
            return math.hypot(p.x - x, p.y - y) < 0.02 or f"the robot at ({p.x:.3f}, {p.y:.3f})"
        self.wait_named(there, CALL_TIMEOUT, f"the robot at ({x}, {y})")

    def robot_patch(self, with_robot, without, label):
        """The pixels the robot changes between two frames: ``(count, centroid, stray)`` over the window."""
        x0, y0 = xscreen.PYBULLET_SCENE_BOX[:2]
        mask = np.zeros(with_robot.shape[:2], dtype=bool)
        x1, y1 = xscreen.PYBULLET_SCENE_BOX[2:]
        mask[y0:y1, x0:x1] = xscreen.changed(with_robot, without)[y0:y1, x0:x1]
        count, centre, stray = xscreen.patch(mask, PATCH_RADIUS)
        print(f"view_gui: robot {label}: {count} changed px, centre {centre}, {stray} stray", flush=True)
        return count, centre, stray

    def check_robot(self, with_robot, without, at, label):
        count, centre, stray = self.robot_patch(with_robot, without, label)
        self.assertGreaterEqual(count, ROBOT_MIN_PIXELS, f"{label}: the robot changes {count} pixels "
                                f"(at least {ROBOT_MIN_PIXELS} expected): no robot drawn")
        self.assertLessEqual(count, ROBOT_MAX_PIXELS, f"{label}: {count} pixels changed, more than a robot")
        self.assertLessEqual(stray, 0.2 * count, f"{label}: {stray} changed pixels away from the robot's patch "
                             f"of {count}")
        want = xscreen.pybullet_pixel((at[0], at[1], ROBOT_Z))
        miss = math.hypot(centre[0] - want[0], centre[1] - want[1])
        print(f"view_gui: robot {label}: drawn at ({centre[0]:.1f}, {centre[1]:.1f}), the camera projects "
              f"({want[0]:.1f}, {want[1]:.1f}): {miss:.1f} px off", flush=True)
        self.assertLess(miss, CENTRE_TOLERANCE, f"{label}: robot drawn at pixel {centre}, the camera puts "
                        f"{at} at {want}: {miss:.1f} px off")
        return centre

    # --------------------------------------------------------------------------------------- tests

    def test_1_world_drawn(self):
        names = self.call(self.world_properties).model_names
        self.assertIn("walls", names)
        self.assertIn(ROBOT, names)
        frame = self.settled("PyBullet's window to show the world", drawn=self.walls_missing)
        viewtest.save_frame(frame, "gui_world")
        counts = xscreen.color_counts(self.scene(frame))
        print(f"view_gui: strong colours with the room: {counts}", flush=True)
        for hue, least in WALL_MIN.items():
            self.assertGreaterEqual(counts[hue], least, f"{counts[hue]} {hue} pixels, the room's walls give "
                                    f"{least} or more: the world is not drawn ({counts})")
        self.view.alive()

    def test_2_robot_where_it_is(self):
        p = self.call(self.get_state, ROBOT, "world").pose.position
        self.assertLess(math.hypot(p.x, p.y), 0.05, f"the robot did not spawn at the origin: {p}")
        at_origin = self.settled("the robot at the origin, drawn")
        self.teleport(*AWAY)
        away = self.settled("the robot out of view, drawn", before=at_origin)
        self.teleport(1.0, 0.0)
        at_x1 = self.settled("the robot at (1, 0), drawn", before=away)
        self.teleport(*AWAY)
        away_again = self.settled("the robot out of view again, drawn", before=at_x1)
        for image, name in ((at_origin, "origin"), (away, "away"), (at_x1, "x1")):
            viewtest.save_frame(image, f"gui_robot_{name}")

        first = self.check_robot(at_origin, away, (0.0, 0.0), "at the origin")
        second = self.check_robot(at_x1, away, (1.0, 0.0), "at (1, 0)")
        # +x on the screen: where the camera maps it, computed, not assumed.
        u0, v0 = xscreen.pybullet_pixel((0.0, 0.0, ROBOT_Z))
        u1, v1 = xscreen.pybullet_pixel((1.0, 0.0, ROBOT_Z))
        want = np.array([u1 - u0, v1 - v0])
        moved = np.array([second[0] - first[0], second[1] - first[1]])
        turn = math.atan2(moved[1], moved[0]) - math.atan2(want[1], want[0])
        angle = abs(math.degrees(math.atan2(math.sin(turn), math.cos(turn))))
        ratio = float(np.linalg.norm(moved) / np.linalg.norm(want))
        print(f"view_gui: 1 m along +x moved the robot's pixels by {moved.round(1).tolist()}, the camera says "
              f"{want.round(1).tolist()}: {angle:.1f} deg apart, length ratio {ratio:.2f}", flush=True)
        self.assertLess(angle, 20.0, f"+x moved the robot's picture by {moved}, the camera maps it to {want}")
        self.assertTrue(0.7 < ratio < 1.4, f"+x moved the robot's picture by {moved}, the camera: {want}")

        # Without a robot in either frame the same check finds no patch worth a robot.
        count, _, _ = self.robot_patch(away_again, away, "in neither frame")
        self.assertLess(count, ROBOT_MIN_PIXELS, f"two frames without the robot differ in {count} pixels: the "
                        "robot check cannot tell a drawn robot from none")
        self.view.alive()

    def test_3_world_check_fails_without_walls(self):
        with_walls = self.wait_named(lambda: self.frame_or_why(), SETTLE_TIMEOUT,
                                     "a screenshot of PyBullet's window before deleting the walls")[0]
        answer = self.call(self.delete_model, "walls")
        self.assertTrue(answer.success, answer.status_message)

        def gone():
            answer = self.poll(self.world_properties)
            if isinstance(answer, str):
                return answer
            return "walls" not in answer.model_names or f"models still there: {answer.model_names}"
        self.wait_named(gone, CALL_TIMEOUT, "the walls to go (/gazebo/get_world_properties)")
        frame = self.settled("PyBullet's window without the walls", before=with_walls)
        viewtest.save_frame(frame, "gui_no_walls")
        counts = xscreen.color_counts(self.scene(frame))
        print(f"view_gui: strong colours without the walls: {counts}", flush=True)
        for hue, least in WALL_MIN.items():
            self.assertLess(counts[hue], least, f"{counts[hue]} {hue} pixels without the walls: test_1's check "
                            f"of {hue} (>= {least}) would not notice the walls missing")
        self.view.alive()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "view_gui", ViewGui, sys.argv)
