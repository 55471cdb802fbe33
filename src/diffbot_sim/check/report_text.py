"""robot_check's report as lines of text: what :func:`diffbot_sim.check.robot_report.build_report` found, the
body at rest and each judged motion (:mod:`diffbot_sim.check.drive_check` results), one screen in all (pure)."""
import math

from diffbot_sim.check import arm_report, robot_report

#: At most this many warning lines are printed (the rest counted), so the report stays one screen.
MAX_WARNINGS = 10


def format_report(report, extra_warnings=()):
    """The report as lines (no trailing newlines). ``extra_warnings``: what bullet_sim logged beyond the
    report's own (merged, duplicates dropped)."""
    lines = [f"model: {report.source} (robot '{report.name}')"]
    mass_ok = abs(report.loaded_mass - report.urdf_mass) <= robot_report.MASS_TOLERANCE
    lines.append(f"mass: URDF {report.urdf_mass:.4f} kg, loaded in PyBullet {report.loaded_mass:.4f} kg"
                 + ("" if mass_ok else f"  (differs by {report.loaded_mass - report.urdf_mass:+.4f} kg)"))
    if not report.drives:
        lines.append("drive: none found (no diff-drive, skid-steer, kobuki or planar-move plugin, and no "
                     "DiffDriveController under libgazebo_ros_control.so)")
    for index, drive in enumerate(report.drives):
        label = "drive" if index == 0 else "also a drive (not used by robot_check)"
        lines.append(f"{label}: {drive.kind} at {drive.where}")
        if drive.note:
            lines.append(f"  {drive.note}")
            continue
        lines.append(f"  wheels: left {', '.join(drive.left)}; right {', '.join(drive.right)}")
        lines.append(f"  separation {_m(drive.separation)} ({drive.separation_from})")
        lines.append(f"  radius {_m(drive.radius)} ({drive.radius_from})")
    lines.append("plugins, sensors and controllers:")
    if not report.items:
        lines.append("  (none)")
    for item in report.items:
        mark = "simulated    " if item.simulated else "NOT simulated"
        what = item.what if item.kind != "sensor" else f"type {item.what}"
        lines.append(f"  {mark}  {item.kind} {item.name} ({what}) {item.where}")
    if report.contacts:
        lines.append("contact sensors:")
        lines.extend(report.contacts)
    lines.extend(arm_report.format_joints(report.joints))
    warnings = robot_report.unique(list(report.warnings) + list(extra_warnings))
    lines.append(f"warnings bullet_sim logs at start: {len(warnings) or 'none'}")
    for text in warnings[:MAX_WARNINGS]:
        lines.append(f"  {text}")
    if len(warnings) > MAX_WARNINGS:
        lines.append(f"  ... and {len(warnings) - MAX_WARNINGS} more")
    return lines


def _m(value):
    return "?" if value is None or not math.isfinite(value) else f"{value:.4g} m"


def _mm(value):
    """``value`` to the millimetre, without a "-0.000" for a hair below zero."""
    return f"{round(value, 3) + 0.0:.3f}"


def format_rest(rest):
    """Lines for the body at rest before driving (a :class:`diffbot_sim.check.drive_check.Rest`)."""
    expected = "" if rest.expected is None else f" (its geometry rests at {_mm(rest.expected)} m)"
    lines = [f"at rest (ground truth): height {_mm(rest.height)} m{expected}, tilt {rest.tilt:.3f} rad, "
             f"height varied {rest.spread:.3f} m: {'PASS' if rest.passed else 'FAIL'}"]
    lines.extend(f"  {text}" for text in rest.failures)
    return lines


def _format_ride(ride):
    """Lines for the body during a motion (a :class:`diffbot_sim.check.drive_check.Ride`)."""
    lines = [f"  body (ground truth): height {_mm(ride.low)}..{_mm(ride.high)} m, tilt up to {ride.tilt:.3f} rad: "
             f"{'PASS' if ride.passed else 'FAIL'}"]
    lines.extend(f"    {text}" for text in ride.failures)
    return lines


def format_motions(straight, turn, straight_body=None, turn_body=None, strafe=None, strafe_body=None):
    """Lines for the judged motions (:mod:`diffbot_sim.check.drive_check` results) and, when given, the body
    during each (:class:`~diffbot_sim.check.drive_check.Ride`); ``straight``/``turn`` may be None when the motion
    could not be run; ``strafe`` (a holonomic base's sideways run) None when not run."""
    lines = []

    def judged(headline, result, body):
        lines.append(f"{headline}: {'PASS' if result.passed else 'FAIL'}")
        lines.extend(f"  {text}" for text in result.failures)
        if body is not None:
            lines.extend(_format_ride(body))
    if straight is not None:
        judged(f"straight 0.2 m/s x 4 s: odometry {straight.odom_distance:.3f} m, ground truth "
               f"{straight.truth_distance:.3f} m (command {straight.expected:.1f} m); heading change "
               f"{straight.odom_heading:.3f} / {straight.truth_heading:.3f} rad", straight, straight_body)
    if strafe is not None:
        judged(f"sideways 0.2 m/s x 4 s: odometry {strafe.odom_left:.3f} m, ground truth "
               f"{strafe.truth_left:.3f} m to the left (command {strafe.expected:.1f} m)", strafe, strafe_body)
    if turn is not None:
        judged(f"turn 0.5 rad/s x 4 s: odometry {turn.odom_yaw:.3f} rad, ground truth {turn.truth_yaw:.3f} "
               f"rad (command {turn.expected:.1f} rad), moved {turn.moved:.3f} m", turn, turn_body)
    return lines

