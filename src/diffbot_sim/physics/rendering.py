"""Camera images of a PyBullet world: PyBullet's CPU TinyRenderer, or its EGL plugin (OpenGL off screen)."""
import pkgutil

from diffbot_sim.physics.client import egl_probe, pybullet, quiet


def render(client, view_pose, width, height, hfov, near, far, renderer="tiny"):
    """A camera image from ``view_pose`` ((x, y, z), (qx, qy, qz, qw)) looking along that frame's +x, up its +z
    (a Gazebo camera): (rgb uint8 (h, w, 3), z-depth float32 (h, w) [m], NaN where nothing was hit or beyond
    ``far``). ``hfov`` [rad] is SDF's horizontal FOV. ``renderer`` "tiny": PyBullet's CPU TinyRenderer; "egl":
    the EGL plugin (:func:`load_egl` must have succeeded; else TinyRenderer draws)."""
    import numpy as np

    from diffbot_sim.sensors import camera as camera_sensor
    eye, target, up = camera_sensor.look_at(view_pose)
    view = pybullet.computeViewMatrix(eye, target, up, physicsClientId=client)
    proj = pybullet.computeProjectionMatrixFOV(camera_sensor.vertical_fov_degrees(hfov, width, height),
                                               width / height, near, far, physicsClientId=client)
    kind = pybullet.ER_BULLET_HARDWARE_OPENGL if renderer == "egl" else pybullet.ER_TINY_RENDERER
    _, _, rgba, depth, _ = pybullet.getCameraImage(width, height, view, proj, renderer=kind,
                                                   flags=pybullet.ER_NO_SEGMENTATION_MASK, physicsClientId=client)
    rgb = np.ascontiguousarray(np.asarray(rgba, np.uint8).reshape(height, width, 4)[:, :, :3])
    return rgb, camera_sensor.linear_depth(np.asarray(depth, np.float32).reshape(height, width), near, far)


def load_egl(client):
    """Load PyBullet's EGL renderer plugin (Mesa's llvmpipe without a GPU) into ``client``: returns (its plugin
    id, None), or (None, why not) for the caller to fall back to TinyRenderer. The plugin only draws bodies
    created after it loads."""
    loader = pkgutil.get_loader("eglRenderer")
    if loader is None:
        return None, "pybullet has no eglRenderer module"
    problem = egl_probe(loader.get_filename())
    if problem is not None:
        return None, problem
    with quiet(1), quiet(2):
        plugin = pybullet.loadPlugin(loader.get_filename(), "_eglRendererPlugin", physicsClientId=client)
    if plugin < 0:
        return None, "pybullet could not load its EGL plugin (no EGL/OpenGL library?)"
    return plugin, None
