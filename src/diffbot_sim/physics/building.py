"""Making PyBullet bodies: a robot from its URDF (fixed links lumped as Gazebo lumps them), a world
description's bodies (one collision shape or a compound), kinematic boxes; and a body's link frame, which
PyBullet does not place (it places the inertial frame)."""
import os
import tempfile

from diffbot_sim.description import lumping
from diffbot_sim.errors import ModelError
from diffbot_sim.physics.client import pybullet, quiet


def load_robot_body(client, urdf_text, model, position, orientation, files):
    """Load a robot's body: returns (PyBullet id, the lumped links' frames). ``model`` is the parsed RobotModel of
    ``urdf_text``; the root link frame is placed at ``position`` turned by the quaternion ``orientation``. The
    URDF PyBullet reads is a temporary file, appended to ``files`` (the caller removes them when it closes).

    Fixed links are lumped as Gazebo lumps them (:mod:`diffbot_sim.description.lumping`), not by PyBullet's
    URDF_MERGE_FIXED_LINKS, which would give inertia-less links 1 kg and a merged body one friction. A robot
    joined to the world (``model.fixed_to_world``) gets a fixed base: PyBullet holds its root where it is
    placed, as Gazebo's joint to the world holds the model (gravity and contacts never move it).

    Raises:
        ModelError: PyBullet could not load it (the model's file named).
    """
    prepared = lumping.lump(urdf_text, model.root, model.surface)
    handle, path = tempfile.mkstemp(prefix=f"{model.name or 'robot'}_", suffix=".urdf")
    with os.fdopen(handle, "w") as out:
        out.write(prepared.text)
    files.append(path)
    flags = pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_USE_IMPLICIT_CYLINDER
    with quiet(1):
        body = pybullet.loadURDF(path, position, orientation, useFixedBase=model.fixed_to_world, flags=flags,
                                 physicsClientId=client)
    if body < 0:
        raise ModelError("PyBullet could not load the model", model.source)
    return body, prepared.frames


def world_body(client, body, mesh_cache):
    """One PyBullet body for ``body`` (a :class:`diffbot_sim.world.bodies.Body`), or None when it has no shape
    to build (a dynamic body's planes are dropped). Static bodies get mass 0; their meshes collide as the
    triangles they are (a hollow ring stays hollow), dynamic ones as convex hulls (what Bullet can simulate).
    World surfaces combine with a robot's by multiplication in Bullet where ODE takes the lower one; so a
    world friction is capped at 1 (Gazebo's ground plane says 100), which makes the product the lower of the
    two whenever either is 1 or more.

    Raises:
        ModelError: a mesh that cannot be read (its file named).
    """
    shapes = [s for s in body.shapes if s.kind != "plane" or body.static]
    if not shapes:
        return None
    index = compound_shape(client, shapes, body.static, mesh_cache)
    mass = 0.0 if body.static else max(body.mass, 1e-6)
    com, com_orn = body.inertial_pose
    uid = pybullet.createMultiBody(baseMass=mass, baseCollisionShapeIndex=index, basePosition=(0, 0, 0),
                                   baseInertialFramePosition=com, baseInertialFrameOrientation=com_orn,
                                   physicsClientId=client)
    # createMultiBody takes the inertial frame's pose as the base pose: place the link frame instead.
    place(client, uid, body.pose, body.inertial_pose)
    options = {}
    mus = [body.shapes[0].surface[k] for k in ("mu", "mu2") if k in body.shapes[0].surface]
    options["lateralFriction"] = min(min(mus), 1.0) if mus else 1.0
    if not body.static:
        ixx, iyy, izz = body.inertia[:3]
        options["localInertiaDiagonal"] = (ixx, iyy, izz)
    pybullet.changeDynamics(uid, -1, physicsClientId=client, **options)
    if body.color is not None:  # the collision-derived visual, coloured (what cameras see)
        pybullet.changeVisualShape(uid, -1, rgbaColor=body.color, physicsClientId=client)
    return uid


def compound_shape(client, shapes, static, mesh_cache):
    """One collision shape index for a body's shapes (a compound when there are several)."""
    from diffbot_sim.description import meshes  # pure; here only to convert world meshes

    c = client
    concave = pybullet.GEOM_FORCE_CONCAVE_TRIMESH if static else 0
    if len(shapes) == 1 and shapes[0].kind == "trimesh":
        shape = shapes[0]
        return pybullet.createCollisionShape(
            pybullet.GEOM_MESH, vertices=shape.vertices.tolist(), indices=shape.indices.ravel().tolist(),
            flags=pybullet.GEOM_FORCE_CONCAVE_TRIMESH, collisionFramePosition=shape.pose[0],
            collisionFrameOrientation=shape.pose[1], physicsClientId=c)
    kinds, radii, halves, lengths, files, scales, normals, flags, positions, orientations = \
        [], [], [], [], [], [], [], [], [], []
    for shape in shapes:
        kind = {"box": pybullet.GEOM_BOX, "cylinder": pybullet.GEOM_CYLINDER, "sphere": pybullet.GEOM_SPHERE,
                "plane": pybullet.GEOM_PLANE, "mesh": pybullet.GEOM_MESH}.get(shape.kind)
        if kind is None:
            continue  # the reader named it already
        kinds.append(kind)
        size = tuple(shape.size) + (0.0, 0.0, 0.0)
        radii.append(size[0] if shape.kind in ("cylinder", "sphere") else 0.0)
        lengths.append(size[1] if shape.kind == "cylinder" else 0.0)
        halves.append(tuple(v / 2.0 for v in size[:3]) if shape.kind == "box" else (0.0, 0.0, 0.0))
        normals.append(size[:3] if shape.kind == "plane" else (0.0, 0.0, 1.0))
        files.append(meshes.convert_cached(shape.mesh, mesh_cache) if shape.kind == "mesh" else "")
        scales.append(tuple(shape.scale) if shape.kind == "mesh" else (1.0, 1.0, 1.0))
        flags.append(concave if shape.kind == "mesh" else 0)
        positions.append(shape.pose[0])
        orientations.append(shape.pose[1])
    if len(kinds) == 1:
        return pybullet.createCollisionShape(
            kinds[0], radius=radii[0], halfExtents=halves[0], height=lengths[0], fileName=files[0],
            meshScale=scales[0], planeNormal=normals[0], flags=flags[0],
            collisionFramePosition=positions[0], collisionFrameOrientation=orientations[0],
            physicsClientId=c)
    return pybullet.createCollisionShapeArray(
        kinds, radii=radii, halfExtents=halves, lengths=lengths, fileNames=files, meshScales=scales,
        planeNormals=normals, flags=flags, collisionFramePositions=positions,
        collisionFrameOrientations=orientations, physicsClientId=c)


def kinematic_box(client, size, pose):
    """A box of ``size`` (x, y, z) [m] centred at ``pose`` ((x, y, z), (qx, qy, qz, qw)) that forces never move
    (mass 0): an actor's body. Returns its PyBullet id."""
    shape = pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[v / 2.0 for v in size],
                                          physicsClientId=client)
    visual = pybullet.createVisualShape(pybullet.GEOM_BOX, halfExtents=[v / 2.0 for v in size],
                                        rgbaColor=(0.85, 0.6, 0.45, 1.0), physicsClientId=client)
    return pybullet.createMultiBody(0.0, shape, visual, pose[0], pose[1], physicsClientId=client)


def place(client, uid, pose, inertial_pose):
    """Put body ``uid``'s link frame at ``pose``, at rest (PyBullet places the inertial frame)."""
    com = pybullet.multiplyTransforms(pose[0], pose[1], inertial_pose[0], inertial_pose[1])
    pybullet.resetBasePositionAndOrientation(uid, com[0], com[1], physicsClientId=client)
    pybullet.resetBaseVelocity(uid, (0, 0, 0), (0, 0, 0), physicsClientId=client)


def link_pose(client, uid, inertial_pose):
    """Link-frame pose of body ``uid`` (whose inertial frame sits at ``inertial_pose``)."""
    com = pybullet.getBasePositionAndOrientation(uid, physicsClientId=client)
    inv = pybullet.invertTransform(inertial_pose[0], inertial_pose[1])
    return pybullet.multiplyTransforms(com[0], com[1], inv[0], inv[1])
