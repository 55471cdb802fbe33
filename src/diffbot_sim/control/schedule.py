"""When a periodic thing is next due (pure): the one rule every plugin, controller and learning environment
schedules its updates and publications by, and when the first one comes after a start or a reset, as Gazebo's
own plugins and sensors time it (docs/reference.md, "First publications after a start or a reset")."""

#: Slack [s] for sim times that should be equal but were summed differently (steps of 1/240 s against 0.2 s).
EPS = 1e-9


def next_due(due, period, now):
    """Next time after ``due`` (a multiple of ``period`` on from it); missed slots are skipped, not burst:
    a schedule that fell behind ``now`` restarts one period after it. ``period`` <= 0: every call (``now``)."""
    if period <= 0:
        return now
    due += period
    if due < now:
        due = now + period
    return due


def first_due_model(now, period):
    """A model plugin's (or a controller's) first update after it (re)starts at sim time ``now``: one ``period``
    later (``period`` <= 0: its first step). Gazebo's model plugins take their last update time at Load (and in
    Reset) and update once a period has passed since it (gazebo_ros_diff_drive, _joint_state_publisher, _p3d,
    _planar_move, _skid_steer_drive, _imu, kobuki's); ros_controllers' ``starting()`` does the same."""
    return now + max(period, 0.0)


def first_due_sensor(scheduled, period, now):
    """A Gazebo sensor's next update when its plugin (re)starts at sim time ``now``, ``scheduled`` being the
    update it had coming (inf: it never ran). A sensor's timer runs on sim time from 0 (Sensor::Load and
    reset_simulation's timeReset set its last update time to 0), so a 5 Hz laser first updates at 0.2 s; one
    spawned later, at its first step. reset_world leaves the timer alone: while sim time goes on (``scheduled``
    within one period of ``now``) the sensor keeps its schedule; when sim time went back (reset_simulation) or
    the sensor is new, it starts again at ``period``."""
    period = max(period, 0.0)
    if scheduled > now + period + EPS:
        return period
    return scheduled
