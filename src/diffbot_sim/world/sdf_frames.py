"""The frame graph of one SDF world (pure): the scopes names are looked up in (the world, each model), their
links, ``<frame>``s and joints, and every frame's world pose as SDF 1.7+ resolves it: ``relative_to`` naming a
model, a link, ``model::link``, a ``<frame>`` or a joint (1.5/1.6's ``frame`` attribute before its rename), and
1.8's ``placement_frame``. :mod:`diffbot_sim.world.sdf_reader` builds the graph while it reads the file."""
from diffbot_sim.errors import ModelError
from diffbot_sim.transforms import compose, inverse
from diffbot_sim.world.bodies import IDENTITY


class Scope:
    """A frame scope: the world or one model. Names in ``relative_to`` are looked up here."""

    def __init__(self, name, full, parent):
        self.name = name
        self.full = full
        self.parent = parent
        self.links = {}
        self.models = {}
        self.frames = {}  # name -> (pose, relative_to, attached_to, path)
        self.joints = {}  # name -> (pose, relative_to, child)


class SdfModel(Scope):
    """A ``<model>`` (or an included one) as read: its own pose, what it is relative to, its placement frame."""

    def __init__(self, name, full, parent, src, path):
        super().__init__(name, full, parent)
        self.src = src
        self.path = path
        self.static = False
        self.pose = IDENTITY
        self.relative_to = ""
        self.placement = ""


class SdfLink:
    """A ``<link>`` as read: its pose, collision shapes, inertial and colour."""

    def __init__(self, name, model, src, path):
        self.name = name
        self.model = model
        self.src = src
        self.path = path
        self.pose = IDENTITY
        self.relative_to = ""
        self.shapes = []
        self.mass = 1.0
        self.inertia = (1.0, 1.0, 1.0, 0.0, 0.0, 0.0)
        self.inertial_pose = IDENTITY
        self.color = None


class FrameGraph:
    """World poses of the frames of one world, each resolved once (cached) and cycles refused.

    Args:
        warn: ``warn(text)`` takes a warning for the world's report (a name that is no frame).
    """

    def __init__(self, warn):
        self.warn = warn
        self.cache = {}
        self.active = set()
        self.override = {}  # id(model) -> the pose it is taken to have (resolving a placement frame)

    def world_pose(self, scope, name, src, path):
        """World pose of the frame ``name`` as seen from ``scope`` ('' = the scope's own frame)."""
        key = (id(scope), name)
        if key in self.cache:
            return self.cache[key]
        if key in self.active:
            raise ModelError(f"pose relative_to '{name}' is part of a cycle of frames", src.path, path)
        self.active.add(key)
        try:
            pose = self._resolve(scope, name, src, path)
        finally:
            self.active.discard(key)
        self.cache[key] = pose
        return pose

    def _resolve(self, scope, name, src, path):
        if name == "" or (scope.parent is not None and name == "__model__"):
            return self.model_pose(scope) if scope.parent is not None else IDENTITY
        if scope.parent is None and name == "world":
            return IDENTITY
        if "::" in name:
            head, rest = name.split("::", 1)
            if head in scope.models:
                return self.world_pose(scope.models[head], rest, src, path)
        if name in scope.links:
            link = scope.links[name]
            return compose(self.world_pose(scope, link.relative_to, link.src, f"{link.path}/pose"), link.pose)
        if name in scope.models:
            return self.model_pose(scope.models[name])
        if name in scope.frames:
            pose, rel, attached, fpath = scope.frames[name]
            return compose(self.world_pose(scope, rel or attached, src, f"{fpath}/pose"), pose)
        if name in scope.joints:
            pose, rel, child = scope.joints[name]
            return compose(self.world_pose(scope, rel or child, src, path), pose)
        where = f"model {scope.full}" if scope.parent is not None else "the world"
        self.warn(f"{src.path}: {path}: relative_to '{name}' names no frame of {where}; its own frame is used")
        return self.world_pose(scope, "", src, path)

    def model_pose(self, model):
        """World pose of ``model``'s frame."""
        if id(model) in self.override:
            return self.override[id(model)]
        key = (id(model), "__model__")
        if key in self.cache:
            return self.cache[key]
        if key in self.active:
            raise ModelError("model pose relative_to is part of a cycle of frames", model.src.path, model.path)
        self.active.add(key)
        try:
            pose = compose(self.world_pose(model.parent, model.relative_to, model.src, f"{model.path}/pose"),
                           model.pose)
            if model.placement:
                # The include pose places the placement frame, not the model frame: undo the frame's offset
                # in the model, found by resolving it with the model frame at the origin.
                sub = FrameGraph(self.warn)
                sub.override = {**self.override, id(model): IDENTITY}
                offset = sub.world_pose(model, model.placement, model.src, f"{model.path}/placement_frame")
                pose = compose(pose, inverse(offset))
        finally:
            self.active.discard(key)
        self.cache[key] = pose
        return pose

    def link_pose(self, link):
        """World pose of ``link``'s frame, as the file places it."""
        return compose(self.world_pose(link.model, link.relative_to, link.src, f"{link.path}/pose"), link.pose)
