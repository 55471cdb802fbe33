"""The simulator's loop: one thread owns PyBullet and sim time; it steps the world, asks every robot's plugins
what is due and publishes /clock and /tf (rospy). Subscriber and service callbacks only hand data to it
(``call``/``post``); it knows no plugin by name."""
import math
import sys
import time

import rospy
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty, EmptyResponse
from tf2_msgs.msg import TFMessage

from diffbot_sim.config import wants_ray_process
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.physics import World
from diffbot_sim.plugins.base import next_due, publisher
from diffbot_sim.simulator.loop_requests import LoopRequests
from diffbot_sim.simulator.subscriber_links import SubscriberLinks
from diffbot_sim.simulator.sync import NodeSync
from diffbot_sim.simulator.throttle import Throttle

#: Wall seconds between two reports of the achieved real-time factor in fast mode.
RTF_REPORT_PERIOD = 30.0
#: Wall seconds the loop's thread keeps the interpreter lock before handing it to a waiting rospy thread
#: (Python's default is 5 ms). PyBullet's calls keep the lock, so in fast mode the loop holds it all the time
#: but for these hand-overs; a service call or a new connection crosses a dozen of them (accept, header,
#: request, hand-over to the loop, reply), each a full interval late: at 5 ms, reset_simulation took
#: 46-154 ms. See docs/performance.md for the figures at this value.
GIL_SWITCH_INTERVAL = 0.0005
#: At most this many physics steps run in one go with no Python in between (``Simulator._batch``): steps that
#: no plugin, clock or service has work before. A bound on how long a request waits in fast mode.
MAX_BATCH_STEPS = 100
#: In real time, sim time that falls behind the wall clock by more than this many wall seconds (a spawn, a slow
#: service, a busy machine) is not made up: pacing starts again from where the simulation is, as Gazebo's
#: World::Step paces each step from the last (sim time never races ahead to catch up). Smaller lags (a late
#: wake-up) are made up, so that RTF stays 1 on average.
MAX_CATCH_UP = 0.05
_new_time = object.__new__  # a rospy.Time without its constructor (see Simulator.stamp)


class RobotRuntime:
    """One robot: its physics body and its plugins (one per Gazebo plugin, found through the registry).

    The loop asks it what is due and calls it before and after each step; it knows no plugin by name.
    """

    def __init__(self, name, ctx, plugins):
        self.name = name  # the model name the /gazebo services know it by
        self.ctx = ctx
        self.plugins = plugins

    def close(self):
        """Remove every topic and service of its plugins (delete_model), and what they hold besides."""
        for plugin in self.plugins:
            plugin.close()
        self.ctx.close()

    def publishers(self):
        """This robot's publishers that the loop writes to."""
        pubs = []
        for plugin in self.plugins:
            pubs += plugin.publishers()
        return pubs

    def next_publish(self):
        """Sim time of this robot's next publication."""
        return min([p.next_publish() for p in self.plugins], default=math.inf)

    def next_control(self):
        """Sim time at which one of this robot's plugins has control work before a step."""
        return min([p.next_control() for p in self.plugins], default=math.inf)

    def next_work(self):
        """Sim time of the next thing this robot must do (control or publishing)."""
        return min([p.next_control() for p in self.plugins] + [self.next_publish()], default=math.inf)

    def before_step(self, now):
        for plugin in self.plugins:
            plugin.before_step(now)

    def after_step(self, now, stamp, transforms):
        for plugin in self.plugins:
            plugin.after_step(now, stamp, transforms)

    def reset(self, now):
        for plugin in self.plugins:
            plugin.reset(now)

    def start(self, now):
        for plugin in self.plugins:
            plugin.start(now)


class Simulator(LoopRequests):
    """The single-threaded loop: apply commands -> step -> publish, paced to the wall clock or not."""

    def __init__(self, cfg):
        LoopRequests.__init__(self)
        self.cfg = cfg
        self.throttle = Throttle(5.0)
        self.paused = False
        self.steps = 0
        self._time_base, self._steps_base = 0.0, 0  # sim time at the step count where the step last changed
        self.world = World(cfg.time_step, cfg.gravity, gui=cfg.gui,
                           ray_process="later" if cfg.ray_process == "auto" else cfg.ray_process)
        self.clock_pub = publisher("/clock", Clock)
        self.tf_pub = publisher("/tf", TFMessage)
        self.robots = []
        self.clock_period = 1.0 / cfg.clock_rate
        self.next_clock = 0.0
        # /clock's wall-time floor (see _publish_clock): ticks closer than this in wall time are coalesced
        self.clock_min_gap = 1.0 / cfg.clock_max_wall_rate if cfg.clock_max_wall_rate > 0 else 0.0
        self._clock_wall = -math.inf  # wall time of the last /clock published
        self._clock_coalesced = False  # a tick was left out since the last one published
        self._next_publish = 0.0  # sim time of the earliest publication due, over clock and every robot
        self._tf_msg = ros_msgs.tf_message([])
        self._clock_msg = ros_msgs.clock(rospy.Time(0))
        self.owns_clock = False  # main() sets it when use_sim_time made rospy follow /clock
        self.world_description = None  # the world file's, when ~world names one
        self.links = SubscriberLinks(self.publishers, cfg.send_timeout, 0.0 if cfg.real_time else cfg.fast_batch)
        self.api = None  # the /gazebo services (simulator.gazebo_services.GazeboApi), when ~enable_ros_network
        self.paused = cfg.paused
        self.actors = None  # the world's <actor>s (simulator.actors.Actors), when it has any
        self.sync = NodeSync(cfg.wait_for_nodes_timeout, cfg.wait_for_nodes_ignore, rospy.get_name(), self.warn)
        self._sensor_pubs = None  # the sensor plugins' publishers (NodeSync), rebuilt when robots change
        self._next_commander_scan = 0.0  # wall time of the next look at who publishes commands (NodeSync)
        self._rtf_mark = None  # (wall, sim, waited) at the last achieved-RTF report
        self._paced_for_lag = False  # fast mode paced at real time for a lagging node (set by _lagging_node)

    def publishers(self):
        """Every publisher the loop writes to (SubscriberLinks tunes and batches their connections)."""
        pubs = [self.clock_pub, self.tf_pub] + (self.api.publishers() if self.api is not None else [])
        for runtime in self.robots:
            pubs += runtime.publishers()
        return pubs

    def warn(self, key, text):
        """A throttled warning (wall time): at most one per key per 5 s, with a count of what was held back."""
        if self.throttle.ready(key, time.monotonic()):
            held = self.throttle.take_suppressed(key)
            rospy.logwarn(text + (f" ({held} more since the last warning)" if held else ""))

    def pause(self):
        self.paused = True

    def unpause(self):
        if self.paused:
            self.paused = False
            self._rebase()

    def reset_world(self):
        """gazebo_ros reset_world: every model back to its start pose at rest, plugins reset; sim time goes
        on."""
        self.world.reset()
        now = self.sim_time
        for runtime in self.robots:
            runtime.reset(now)
            runtime.start(now)
        if self.api is not None:
            self.api.wrenches.clear_all()
            self.api.reset()
        if self.actors is not None:
            self.actors.reset(now)

    def reset_simulation(self):
        """gazebo_ros reset_simulation: as reset_world, and sim time back to 0 (/clock jumps back, as in
        Gazebo)."""
        self.steps = 0
        self._time_base, self._steps_base = 0.0, 0
        self.next_clock = 0.0
        self._next_publish = 0.0
        self.reset_world()
        self._publish_clock(0.0)
        self._rebase()

    def add_robot(self, runtime, now=None):
        """A robot joins the loop; one spawned while running starts at the current sim time."""
        self.robots.append(runtime)
        self._sensor_pubs = None
        self.consider_ray_process()
        if now is not None:
            runtime.start(now)
            self._next_publish = min(self._next_publish, now)

    def remove_robot(self, runtime):
        """delete_model: the robot's topics, services and body go."""
        self.robots.remove(runtime)
        self._sensor_pubs = None
        runtime.close()
        self.world.remove_robot(runtime.ctx.robot)

    def set_update_rate(self, rate):
        """set_physics_properties' max_update_rate: steps per wall second (0: as fast as possible)."""
        if rate > 0:
            self.cfg.real_time, self.cfg.real_time_factor = True, rate * self.cfg.time_step
        else:
            self.cfg.real_time = False
        self._rebase()
        self.consider_ray_process()

    def consider_ray_process(self):
        """Start the ray process when ``~ray_process`` wants it now (``config.wants_ray_process``: auto counts
        the ray sensors' rays per sim second, in real time)."""
        if self.cfg.ray_process != "auto" or self.world.ray_helper is not None:
            return
        rays = sum(plugin.rays_per_second() for runtime in self.robots for plugin in runtime.plugins)
        if wants_ray_process(self.cfg.ray_process, self.cfg.real_time, rays):
            self.world.start_ray_process()
            rospy.loginfo(f"bullet_sim: the ray sensors cast {rays:,.0f} rays per sim second: casting them in a "
                          "helper process from now on (~ray_process auto; false casts them in this one)")

    @property
    def sim_time(self):
        return self._time_base + (self.steps - self._steps_base) * self.cfg.time_step

    def set_time_step(self, time_step):
        """set_physics_properties' time_step: the physics step [s] from the next step on; sim time goes on from
        where it is."""
        self._time_base, self._steps_base = self.sim_time, self.steps
        self.cfg.time_step = time_step
        self.world.set_time_step(time_step)
        self._rebase()

    def _rebase(self):
        """Re-anchor real-time pacing at the current sim time (after a pause or a start)."""
        self.wall0 = time.monotonic()
        self.sim0 = self.sim_time

    def empty_service(self, action, request=None):
        """A std_srvs/Empty handler: ``action`` on the loop (a reset in fast mode after NodeSync.connect_first)."""
        if action in (self.reset_simulation, self.reset_world) and not self.cfg.real_time and self.cfg.wait_for_nodes:
            self.sync.connect_first(request, self.publishers())
        self.call(action)
        return EmptyResponse()

    def advertise_services(self):
        """The node's own ``~pause_physics``, ``~unpause_physics``, ``~reset_simulation`` and
        ``~reset_world`` (the /gazebo ones' aliases, kept for launch files written for bullet_sim), unless
        the node's private namespace is the /gazebo namespace (empty_world.launch names the node gazebo)."""
        if rospy.get_name().rstrip("/") == self.cfg.gazebo_namespace.rstrip("/"):
            return
        for name, action in (("pause_physics", self.pause), ("unpause_physics", self.unpause),
                             ("reset_simulation", self.reset_simulation), ("reset_world", self.reset_world)):
            rospy.Service("~" + name, Empty, lambda req, action=action: self.empty_service(action, req))

    # -- the loop -----------------------------------------------------------------------------------
    def run(self):
        cfg = self.cfg
        sys.setswitchinterval(GIL_SWITCH_INTERVAL)
        for runtime in self.robots:
            runtime.start(self.sim_time)
        self._publish_clock(self.sim_time)
        self._rebase()
        while not rospy.is_shutdown():
            self._handle_requests()
            if self.paused:
                # Gazebo keeps publishing /clock while paused: nodes that wait for a first /clock (the
                # controller spawner, rospy.sleep) must not hang on a world started paused.
                self._publish_clock(self.sim_time)
                self.links.release()
                self.wake.wait(0.1)
                self.wake.clear()
                continue
            limit = MAX_BATCH_STEPS
            if cfg.real_time or self._paced_for_lag:
                dt = cfg.time_step
                factor = cfg.real_time_factor if cfg.real_time else 1.0
                limit, target = self._real_time_room(time.monotonic(), factor)
                if limit == 0:
                    # Sleep until the next thing due, or until a command wakes us. Publishing and control,
                    # not stepping, set the wake rate, so CPU stays low.
                    due = min([self.next_clock] + [r.next_work() for r in self.robots])
                    # Wake at the step that reaches ``due`` (steps land on multiples of dt), not at ``due``
                    # itself: waking between steps would only find nothing to do and sleep again.
                    step_at = self._step_reaching(due)
                    wait = (max(step_at, self.sim_time + dt) - target) / factor
                    if self.wake.wait(min(max(wait, 0.0), 0.1)):
                        # A command woke us: it is taken now, and applied by the plugins' before_step at the
                        # next step, once (a plugin's step work is not repeated: PyBullet adds up torques set
                        # twice before one step, and a PID would step twice).
                        self.wake.clear()
                        self._handle_requests()
                    continue
            self._step_once(limit)

    def _lagging_node(self):
        """Fast mode with a node in the loop dropped for lagging and expected back (:meth:`NodeSync.lagging`): sim
        time is then paced at real time until it is taken back. Pacing is re-anchored when that begins (sim time
        ran ahead of the wall clock until then). Asked after each hold (``_wait_for_nodes``), where drops and
        take-backs happen, not at every pass of the loop."""
        lagging = self.cfg.wait_for_nodes and self.sync.lagging()
        if lagging and not self._paced_for_lag:
            self._rebase()
        self._paced_for_lag = lagging
        return lagging

    def _real_time_room(self, wall, factor):
        """Paced at ``factor`` x real time, at wall-clock ``wall``: (how many steps are due now, at most
        MAX_BATCH_STEPS; 0 to wait, the sim time pacing wants). Sim time that fell behind by more than MAX_CATCH_UP
        wall seconds (a stall: a spawn, a slow service, a busy machine) is not made up: pacing starts again from
        here (``_rebase``)."""
        dt = self.cfg.time_step
        target = self.sim0 + (wall - self.wall0) * factor
        if target - self.sim_time > MAX_CATCH_UP * factor + dt:
            self.wall0, self.sim0 = wall - dt / factor, self.sim_time
            target = self.sim_time + dt
        due = int((target - self.sim_time) / dt + 1e-9)
        return max(0, min(MAX_BATCH_STEPS, due)), target

    def _step_reaching(self, due):
        """Sim time of the first step at or after sim time ``due``."""
        dt = self.cfg.time_step
        return self.sim_time + max(0, math.ceil((due - self.sim_time) / dt - 1e-6)) * dt

    def _batch(self, limit):
        """How many physics steps can run now with no Python in between: up to the first step at or after the
        earliest work due (a plugin's control or publication, /clock, the world API's), at most ``limit``; one
        while anything needs every step (a robot being set down, actors, wrenches or efforts being applied).
        Gazebo's plugins run on every world update; ours say when their update has work (``next_control``,
        ``next_publish``), so steps in between are PyBullet's alone: a 1 ms world costs what its physics
        costs."""
        if limit <= 1 or self.world.landing or self.actors is not None or (
                self.api is not None and self.api.busy()):
            return 1
        due = min([self._next_publish] + [r.next_control() for r in self.robots])
        if due == math.inf:
            return limit
        steps = math.ceil((due - self.sim_time) / self.cfg.time_step - 1e-6)
        return max(1, min(limit, steps))

    def _step_once(self, limit=1):
        now = self.sim_time
        for runtime in self.robots:
            runtime.before_step(now)
        if self.actors is not None:
            self.actors.before_step(now)
        if self.api is not None:
            self.api.before_step(now)
        count = self._batch(limit)
        self.world.step(count)
        self.steps += count
        now = self.sim_time
        if now + 1e-9 < self._next_publish:
            if self.links.held_since is not None:
                self.links.release_if_due(time.monotonic())
            return  # most steps publish nothing: skip building a stamp and asking every robot
        stamp = self.stamp()
        wall = time.monotonic()
        self.links.tune_new(wall)
        self.links.hold(wall)
        transforms = []
        for runtime in self.robots:
            runtime.after_step(now, stamp, transforms)
        if transforms and self.tf_pub.get_num_connections():
            self._tf_msg.transforms = transforms
            self.tf_pub.publish(self._tf_msg)
        if self.api is not None:
            self.api.after_step(now, stamp)
        ticked = now + 1e-9 >= self.next_clock
        if ticked:
            # Nodes in the loop see every tick (their timers run on it; the simulator waits for them after each);
            # only a clock nobody waits on is coalesced to the wall-time cap.
            waits = not self.cfg.real_time and self.cfg.wait_for_nodes and self.sync.in_loop()
            ticked = self._publish_clock(now, None if waits else wall)
        if not self.cfg.real_time and self.cfg.wait_for_nodes:
            self._wait_for_nodes(ticked)
        self._next_publish = min([self.next_clock] + [r.next_publish() for r in self.robots]
                                 + ([self.api.next_publish()] if self.api is not None else []))
        self.links.release_if_due(wall)

    def _wait_for_nodes(self, ticked):
        """Fast mode: hold sim time until the nodes fed by this step's sensor messages answered them, and
        after a /clock tick until the nodes in the loop are idle (:mod:`diffbot_sim.simulator.sync`)."""
        if self._sensor_pubs is None:
            self._sensor_pubs = [pub for runtime in self.robots for plugin in runtime.plugins if plugin.sensor
                                 for pub in plugin.publishers()]
        fresh = self.sync.published(self._sensor_pubs)
        if ticked:
            wall = time.monotonic()
            if wall >= self._next_commander_scan:  # who publishes commands changes rarely: looked at 10 times a s
                self._next_commander_scan = wall + 0.1
                self.sync.note_commanders(self._command_subscribers())
        if fresh and self._clock_coalesced:
            self._send_clock()  # the nodes fed now see a clock as new as the data
        if fresh or (ticked and (self.sync.listeners or self.sync.commanders)):
            self.links.release()
            self.sync.forget_drops(fresh)
            self.sync.wait(fresh, self._serve_while_held, lambda: self.paused or rospy.is_shutdown())
            self._lagging_node()
        self._report_rtf()

    def _command_subscribers(self):
        """The simulator's subscriptions that command it: every robot's (cmd_vel, controller commands) and the
        world API's (set_model_state, set_link_state)."""
        handles = [h for runtime in self.robots for h in runtime.ctx.handles]
        if self.api is not None:
            handles += self.api.handles
        return [h for h in handles if isinstance(h, rospy.Subscriber)]

    def _serve_while_held(self):
        """Requests keep being served while sim time is held (a reset, a spawn, a step-and-wait client's
        services); a change of the model set is published at once (clients watch model_states for it)."""
        self._handle_requests()
        if self.api is not None:
            self.api.publish_if_changed(self.sim_time, self.stamp())

    def _report_rtf(self):
        wall = time.monotonic()
        if self._rtf_mark is None:
            self._rtf_mark = (wall, self.sim_time, self.sync.waited)
            return
        wall0, sim0, waited0 = self._rtf_mark
        if wall - wall0 < RTF_REPORT_PERIOD:
            return
        rtf = (self.sim_time - sim0) / (wall - wall0)
        held = (self.sync.waited - waited0) / (wall - wall0)
        rospy.set_param("~achieved_rtf", round(rtf, 3))
        rospy.loginfo(f"bullet_sim: fast mode, real-time factor {rtf:.1f} over the last {wall - wall0:.0f} s "
                      f"(waiting for the nodes in the loop {100 * held:.0f} % of the time)")
        self._rtf_mark = (wall, self.sim_time, self.sync.waited)

    def stamp(self):
        """Sim time as a rospy.Time from integer nanoseconds, its canonical fields set without the constructor's
        checks (a few per cent of a 1 ms effort arm's loop)."""
        stamp = _new_time(rospy.Time)
        stamp.secs, stamp.nsecs = divmod(round(self.sim_time * 1e9), 1_000_000_000)
        return stamp

    def _publish_clock(self, now, wall=None):
        """Publish /clock at ``now`` (its tick due); returns whether it was sent.

        With ``wall`` (a tick of the running loop), a tick that comes sooner than ``clock_min_gap`` wall seconds
        after the last one sent is left out (coalesced: the next one sent carries the newer time). Why: every
        node with use_sim_time receives every /clock in a Python callback; far above real time (RTF 50 at
        100 Hz is 5,000 a second) that starves the node's other threads (a service call through a fresh
        ServiceProxy took 275 ms instead of 5 ms). A node sees /clock at most ``clock_max_wall_rate`` times
        a wall second, as often as at 5x real time. Nodes in the loop get every tick (``_step_once`` gives no
        ``wall``): the simulator waits for them after each, so they are never flooded, and their timers fire at
        the sim times they would at real time. A pause, a reset and a start always publish."""
        self.next_clock = next_due(self.next_clock, self.clock_period, now)
        return self._send_clock(wall)

    def _send_clock(self, wall=None):
        """/clock at the current sim time, unless ``wall`` is given and too soon (see _publish_clock)."""
        stamp = self.stamp()
        if self.owns_clock:
            rospy.rostime._set_rostime(stamp)  # this node's own sim time (see nodes/sim_node.py's _own_the_clock)
        if wall is not None and wall - self._clock_wall < self.clock_min_gap:
            self._clock_coalesced = True
            return False
        self._clock_wall = wall if wall is not None else time.monotonic()
        self._clock_coalesced = False
        if self.clock_pub.get_num_connections():
            self._clock_msg.clock = stamp
            self.clock_pub.publish(self._clock_msg)
        return True

    def close(self):
        self.links.release()
        if self.api is not None:
            self.api.close()
        self.world.close()
