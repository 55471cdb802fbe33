#!/usr/bin/env python3
"""view_rviz suite: ``view.launch`` under Xvfb, real rviz, judged by its screen and by ROS.

view_robot.urdf in laser_room.world (east wall face at x = 2.9 m, see the world's comment), top view.

- Status: rviz 1.14 has no status topic and does not log display statuses, so they are read where rviz
  shows them: each display's name in the Displays panel is drawn blue (Ok), orange (Warn) or red (Error)
  (xscreen.STATUS_*). No orange or red pixel may be there; plus no WARN/ERROR from /rviz on /rosout, rviz
  subscribed to every display's topic (master) and received messages on each (its getBusStats).
- The robot: a frame with the RobotModel display and one without it (rviz ~load_config) differ where the
  robot is drawn; that patch's centre must be where /odom puts the robot through the view's centre and
  scale, and its size the robot's top. Then the robot drives 1 m and the same check runs again: a picture
  that did not follow the robot fails it (asserted too: the old patch is far from the new pose).
- The scan: exact scan-green pixels along the east wall's face while facing it, none with the LaserScan
  display off, and still on the wall after the drive (points in the fixed frame stay on the walls).
"""
import math
import os
import sys
import tempfile
import time

import numpy as np
import rospy
import rostest
import viewtest

from diffbot_sim.view import (
    rviz_config,
    xscreen,
)

START_TIMEOUT = 60.0  # s wall: master, simulator, rviz under llvmpipe on a busy 2-core machine
SETTLE_TIMEOUT = 60.0  # s wall: rviz, drawing at 1 frame/s on a busy 2-core machine, loads a config and settles
STABLE_WALL = 1.5  # s wall: the 3-D view (outside laser points) unchanged this long: rviz has drawn it
#: Pixels (outside laser points) two settled frames may differ in: a body at rest still moves by micrometres
#: in the physics, and rviz's anti-aliased edges of the robot and its TF axes flip a few pixels (seen: 2-8
#: at the robot's outline, none elsewhere); a config still loading changes hundreds.
SETTLE_CHANGED = 20
EAST_WALL_X = 2.9  # m, laser_room.world
ROBOT_TOP = (0.26, 0.18)  # m, view_robot.urdf's base visual: what the top view sees of the robot
SCAN_GREEN = np.array([int(c) for c in rviz_config.SCAN_COLOR.split(";")], dtype=np.uint8)
CENTRE_TOLERANCE = 0.05
DRIVE = 1.0  # m the robot drives forward between the two pictures (to x = 1, clear of the east wall at 2.9)
DRIVE_TIMEOUT = 60.0  # s wall: 2.5 s of sim time at 0.4 m/s, on a machine where the simulator runs slower
#: m: the robot's top fits in this circle (half-diagonal 0.16 m), the next wall does not; the laser and camera
#: visuals shift the patch's centre forward ~1 cm
PATCH_RADIUS = 0.3


class ViewRviz(viewtest.PictureSuite):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_view_rviz")
        if not cls.start_view("view_rviz", viewtest.View([f"model:={viewtest.ROBOT}", f"world:={viewtest.WORLD}"],
                                                         "view_rviz_launch"), ready=cls.rviz_up):
            return
        cls.tmp = tempfile.mkdtemp(prefix="view_rviz_")
        cls.view.wait(lambda: cls.view.last_odom() is not None, START_TIMEOUT, "odometry")
        cls.config = viewtest.generated_config()
        current = cls.config["Visualization Manager"]["Views"]["Current"]
        cls.center, cls.scale = (current["X"], current["Y"]), current["Scale"]
        cls.full = viewtest.config_variant(cls.config, os.path.join(cls.tmp, "full.rviz"))
        cls.no_model = viewtest.config_variant(cls.config, os.path.join(cls.tmp, "no_model.rviz"), RobotModel=False)
        cls.no_scan = viewtest.config_variant(cls.config, os.path.join(cls.tmp, "no_scan.rviz"), LaserScan=False)

    # ------------------------------------------------------------------------------------- helpers

    @classmethod
    def rviz_up(cls):
        """rviz started: its window at its configured size, its services (advertised right after rviz shows the
        window), and its first settled view (``settled``): the start-up in which a death of rviz itself is
        met by starting the view once more (``PictureSuite.start_view``)."""
        started = time.monotonic()
        cls.view.wait(lambda: cls.rviz_window(), START_TIMEOUT, "the rviz window")
        window = time.monotonic() - started
        cls.view.wait(lambda: cls.view.service_up("/rviz/load_config_discarding_changes"), 20.0, "rviz's services")
        services = time.monotonic() - started
        cls.settled("rviz started")
        print(f"rviz up: its window after {window:.1f} s, its services after {services:.1f} s, settled (every "
              f"display Ok) after {time.monotonic() - started:.1f} s (from the launch's start)", flush=True)

    @classmethod
    def rviz_window(cls, windows=None):
        """rviz's main window once it has its configured size (it opens at 640 x 480 first)."""
        for window in cls.view.windows() if windows is None else windows:
            if window.name.endswith("RViz") and (window.width, window.height) == xscreen.SCREEN:
                return window
        return None

    @classmethod
    def layout(cls):
        """(rviz window, 3-D view panel, status mask over the screen: the left dock without render panels), or
        a sentence saying what is missing (rviz maps, resizes and re-parents its windows while it starts and
        while it loads a config: a missing window is "not yet", not a failure)."""
        windows = cls.view.windows()
        top = cls.rviz_window(windows)
        if top is None:
            names = sorted({w.name for w in windows if w.name})[:8]
            return f"no rviz window of {xscreen.SCREEN[0]}x{xscreen.SCREEN[1]} (named windows: {names})"
        inside = xscreen.subtree(windows, top)
        panels = [w for w in inside if not w.name]
        if not panels:
            return "the rviz window has no render panel yet"
        view = max(panels, key=lambda w: w.area)
        mask = np.zeros((xscreen.SCREEN[1], xscreen.SCREEN[0]), dtype=bool)
        mask[view.y:top.y + top.height, top.x:view.x] = True
        for panel in panels:
            x0, y0, x1, y1 = panel.box()
            mask[y0:y1, x0:x1] = False
        return top, view, mask

    @classmethod
    def settled(cls, what):
        """Wait until rviz shows what it was told to, at rest; return (frame, 3-D view panel).

        Three conditions, each named in the failure message when it is the one that never held:
        - rviz's window and its 3-D panel are there (``layout``);
        - every display's name is drawn in the Ok colour, none in Warn or Error (a display still loading, or
          one without data, is Warn);
        - the 3-D view is the same, outside the laser points and but for SETTLE_CHANGED edge pixels, in every
          screenshot over STABLE_WALL seconds (at least two): rviz has drawn the loaded config and nothing in it
          moves. Laser points are left
          out because each scan moves them by its noise, and on a slow machine (rviz at 1 frame/s, a
          screenshot taking longer than a scan period) two screenshots never span the same scan.
        """
        history = []  # (wall time, view box, view pixels, laser-point mask) of the screenshots so far
        cls.why = "no screenshot taken"

        def ready():
            found = cls.layout()
            if isinstance(found, str):
                cls.why, history[:] = found, []
                return None
            _, view, mask = found
            frame = cls.view.screenshot()
            status = xscreen.status_colors(frame, mask)
            if status["warn"] or status["error"] or not status["ok"]:
                cls.why, history[:] = f"display status colours {status} (Ok > 0, Warn and Error 0 wanted)", []
                return None
            pixels = xscreen.crop(frame, view.box())
            history.append((time.monotonic(), view.box(), pixels, xscreen.greenish(pixels)))
            now, box = history[-1][0], history[-1][1]
            moved, where = 0, None
            for _, other_box, other, laser in history[:-1]:
                if other_box != box or other.shape != pixels.shape:
                    moved = -1
                    break
                diff = xscreen.changed(other, pixels, 0) & ~(laser | history[-1][3])
                if diff.sum() > moved:
                    moved, where = int(diff.sum()), xscreen.blob(diff)[2]
                    viewtest.save_frame(other, "settle_before")
                    viewtest.save_frame(pixels, "settle_after")
            if moved < 0 or moved > SETTLE_CHANGED:
                cls.why = ("the 3-D panel moved or was resized" if moved < 0 else
                            f"the 3-D view changed in {moved} pixels (> {SETTLE_CHANGED}) outside the laser points "
                            "between screenshots, "
                            f"within the panel's pixels {where} (rviz still drawing, or something still moving; "
                            "settle_before/after.png in ROS_HOME)")
                history[:] = history[-1:]
                return None
            if len(history) < 2 or now - history[0][0] < STABLE_WALL:
                cls.why = f"the 3-D view unchanged for {now - history[0][0]:.1f} s of the {STABLE_WALL:g} s wanted"
                return None
            return frame, view
        started = time.monotonic()
        try:
            found = cls.view.wait(ready, SETTLE_TIMEOUT, what)
            print(f"{what}: settled in {time.monotonic() - started:.1f} s", flush=True)
            return found
        except AssertionError as err:
            raise AssertionError(f"{what}: {cls.why} ({err})") from None

    def robot_patch(self, with_model, without_model, view):
        """The pixels the RobotModel display changes: ``(count, centroid, stray)``. Laser points are left
        out: a scan arrives every 0.2 s and its squares land a pixel apart from one scan to the next."""
        a, b = xscreen.crop(with_model, view.box()), xscreen.crop(without_model, view.box())
        scan = xscreen.greenish(a) | xscreen.greenish(b)
        return xscreen.patch(xscreen.changed(a, b) & ~scan, PATCH_RADIUS * self.scale)

    def expected_pixel(self, view, x, y):
        u, v = xscreen.top_view_pixel(x, y, view, self.center, self.scale)
        return u - view.x, v - view.y  # in the panel's own pixels, as robot_patch gives them

    def wall_green(self, frame, view):
        """Scan-green pixels within a point's size of the east wall's face, and green pixels anywhere."""
        u_wall, _ = xscreen.top_view_pixel(EAST_WALL_X, 0.0, view, self.center, self.scale)
        green = np.all(frame == SCAN_GREEN, axis=2)
        band = np.zeros_like(green)
        band[view.y:view.y + view.height, int(u_wall - 0.08 * self.scale):int(u_wall + 2)] = True
        return int((green & band).sum()), int(green.sum())

    def check_robot_at(self, pose, label):
        self.view.load_config(self.full)
        with_model, view = self.settled(f"rviz settled with the robot ({label})")
        self.view.load_config(self.no_model)
        without_model, view2 = self.settled(f"rviz settled without the robot model ({label})")
        self.assertEqual(view.box(), view2.box(), "the 3-D view moved between the two frames")
        viewtest.save_frame(with_model, f"rviz_{label.replace(' ', '_')}_model")
        viewtest.save_frame(without_model, f"rviz_{label.replace(' ', '_')}_no_model")
        count, centre, stray = self.robot_patch(with_model, without_model, view)
        area = ROBOT_TOP[0] * ROBOT_TOP[1] * self.scale ** 2
        self.assertGreater(count, 0.5 * area, f"{label}: the robot model changes {count} pixels, the robot's top "
                           f"is {area:.0f} at scale {self.scale} px/m: no robot drawn")
        self.assertLess(count, 2.0 * area, f"{label}: the robot model changes {count} pixels, expected about "
                        f"{area:.0f}")
        self.assertLess(stray, 0.2 * count, f"{label}: {stray} changed pixels away from the robot's patch")
        want = self.expected_pixel(view, pose[0], pose[1])
        miss = math.hypot(centre[0] - want[0], centre[1] - want[1]) / self.scale
        self.assertLess(miss, CENTRE_TOLERANCE, f"{label}: robot drawn at pixel {centre}, /odom says {want} "
                        f"(pose {pose}): {miss:.3f} m off")
        return with_model, view, centre

    # --------------------------------------------------------------------------------------- tests

    def test_1_displays_ok_and_fed(self):
        self.settled("every display Ok")
        subs = self.view.subscriptions("/rviz")
        for topic in ("/odom", "/scan", "/front_camera/image_raw", "/world_markers", "/tf", "/tf_static"):
            self.assertIn(topic, subs, f"rviz does not subscribe {topic}; it subscribes {subs}")
        counts = self.view.wait(lambda: (lambda c: c if all(c.get(t, 0) > 0 for t in (
            "/odom", "/scan", "/front_camera/image_raw", "/world_markers", "/tf")) else None)(
            self.view.received("/rviz")), 20.0, "rviz to receive messages on every display's topic")
        self.assertGreater(counts["/odom"], 0)
        self.assertEqual(self.view.errors_from("/rviz"), [], "rviz logged warnings or errors")
        self.assertIsNotNone(self.view.node_uri("/world_markers"), "world_markers is not running")

    def test_2_robot_and_scan_where_they_are(self):
        odom = self.view.last_odom().pose.pose.position
        with_model, view, first = self.check_robot_at((odom.x, odom.y), "at the start")
        on_wall, _ = self.wall_green(with_model, view)
        self.assertGreater(on_wall, 100, "no scan points drawn on the east wall the robot faces")
        self.view.load_config(self.no_scan)
        no_scan, view = self.settled("rviz settled without the LaserScan display")
        self.assertEqual(self.wall_green(no_scan, view)[0], 0, "scan-green pixels on the wall with the LaserScan "
                         "display off")

        self.view.drive_until(0.4, 0.0, lambda: self.view.last_odom().pose.pose.position.x - odom.x >= DRIVE,
                              DRIVE_TIMEOUT, f"the robot to drive {DRIVE} m forward (/odom)")
        self.view.wait(lambda: abs(self.view.last_odom().twist.twist.linear.x) < 1e-3, 20.0, "the robot to stop")
        moved = self.view.last_odom().pose.pose.position
        with_model, view, second = self.check_robot_at((moved.x, moved.y), "after driving 1 m")
        stale = math.hypot(first[0] - second[0], first[1] - second[1]) / self.scale
        self.assertGreater(stale, 5 * CENTRE_TOLERANCE, "the picture of the robot did not move with it")
        on_wall, _ = self.wall_green(with_model, view)
        self.assertGreater(on_wall, 100, "after the drive the scan points are no longer on the east wall")
        self.assertEqual(self.view.errors_from("/rviz"), [], "rviz logged warnings or errors")
        self.view.alive()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "view_rviz", ViewRviz, sys.argv)
