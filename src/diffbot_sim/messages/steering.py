"""four_wheel_steering_msgs of the simulated four_wheel_steering_controller (message module only, no rospy).

four_wheel_steering_msgs is not a Debian package: it comes from the overlay (``overlay/four_wheel_steering_msgs``),
so it is imported lazily and the rest of the package loads without it.
"""
from std_msgs.msg import Header


def four_wheel_steering_msgs():
    """The ``four_wheel_steering_msgs.msg`` module (ImportError when the overlay is left out)."""
    from four_wheel_steering_msgs import msg

    return msg


def four_wheel_steering_command(message):
    """A ``FourWheelSteering`` command as (speed m/s, front steering rad, rear steering rad)."""
    return message.speed, message.front_steering_angle, message.rear_steering_angle


def odom_steer(stamp, frame, speed, acceleration, jerk, front, front_velocity, rear, rear_velocity):
    """``FourWheelSteeringStamped`` as the controller's ``odom_steer`` carries it."""
    msg = four_wheel_steering_msgs()
    out = msg.FourWheelSteeringStamped(header=Header(stamp=stamp, frame_id=frame))
    data = out.data
    data.speed, data.acceleration, data.jerk = speed, acceleration, jerk
    data.front_steering_angle, data.front_steering_angle_velocity = front, front_velocity
    data.rear_steering_angle, data.rear_steering_angle_velocity = rear, rear_velocity
    return out
