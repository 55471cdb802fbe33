"""What pal-robotics' realsense_gazebo_plugin publishes, as plain numbers (pure): its CameraInfo and its depth image.

* CameraInfo (``cameraInfo`` in gazebo_ros_realsense.cpp): f = width / (2 tan(hfov/2)) for fx and fy, the centre at
  (width/2, height/2) (not gazebo_ros's (width+1)/2), P = [K | 0], R identity, plumb_bob with zero D.
* Depth: 16UC1 in millimetres (DEPTH_SCALE_M 0.001), 0 where the depth is below ``rangeMinDepth``, above
  ``rangeMaxDepth``, beyond 65.535 m or where nothing was hit.
"""
import math

import numpy as np

DEPTH_SCALE_M = 0.001


def realsense_intrinsics(width, height, hfov):
    """(K, P) row-major lists as the plugin fills them."""
    focal = 0.5 * width / math.tan(0.5 * hfov)
    cx, cy = width * 0.5, height * 0.5
    return ([focal, 0.0, cx, 0.0, focal, cy, 0.0, 0.0, 1.0],
            [focal, 0.0, cx, 0.0, 0.0, focal, cy, 0.0, 0.0, 0.0, 1.0, 0.0])


def depth_millimetres(depth, range_min, range_max):
    """uint16 (h, w) of a float depth image [m] (NaN: no hit), clipped as the plugin clips."""
    d = np.nan_to_num(np.asarray(depth, np.float64), nan=-1.0)
    bad = (d < range_min) | (d > range_max) | (d > DEPTH_SCALE_M * 65535) | (d < 0)
    out = np.where(bad, 0.0, d / DEPTH_SCALE_M)
    return np.ascontiguousarray(out.astype(np.uint16))
