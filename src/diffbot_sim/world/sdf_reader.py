"""Read a Gazebo-classic SDF world (``.world``) into a :class:`diffbot_sim.world.bodies.WorldDescription` (pure).

Why our own reader: ``pybullet.loadSDF`` has no ``<include>``, mishandles ``<static>true</static>``, turns
meshes into convex hulls and does not import jointless multi-link models; libsdformat is not on Debian's
Python. So we read the few elements that decide collisions ourselves and name everything else once in
``not_simulated`` so a user sees what the world asked for and did not get.

What is read (SDF 1.4 to 1.9, as Gazebo 11 reads them):

* ``<model>`` (inline, nested as ``outer::inner``) and ``<include>`` (``uri``; ``name``, ``pose`` and
  ``static`` override the included model's, an empty ``<pose/>`` resets it to zero; also inside a model).
  Each ``<link>`` becomes one :class:`~diffbot_sim.world.bodies.Body` named ``model::link``; joints between links
  are named in one warning per model and not simulated (the links move as separate bodies).
* ``<collision>`` geometry box, cylinder, sphere, plane (infinite), mesh, and its surface. Of visuals only the
  colour is read, for cameras: the first ``<visual><material>`` of a link gives ``Body.color``; the camera
  sees the collision geometry in that colour. (One element's values: :mod:`diffbot_sim.world.sdf_elements`.)
* Poses with SDF 1.7+ frame semantics (``relative_to`` naming a model, a link, ``model::link``, a ``<frame>``
  or a joint; 1.5/1.6's ``frame`` attribute is the same attribute before its rename), 1.8
  ``placement_frame``, 1.9 ``degrees`` and ``rotation_format="quat_xyzw"``.
* The first ``<state>``: its model (and nested model and link) poses replace the file's, as Gazebo's
  ``World::SetState`` does at start; its ``insertions`` add models and its ``deletions`` remove them.
* ``<physics>`` gravity, ``max_step_size``, ``real_time_factor`` and ``real_time_update_rate``.

``model://NAME`` is searched as Gazebo does: ``~/.gazebo/models``, each ``GAZEBO_MODEL_PATH`` entry, then the
directories ROS packages export to gazebo_ros (:func:`ros_package_model_paths`); the first match wins.
Gazebo's own ``ground_plane`` and ``sun`` are built in for when no directory has them. Nothing is ever
downloaded: a model that cannot be found is an error that names every directory searched. (Finding and
parsing the files: :mod:`diffbot_sim.world.sdf_files`; resolving the frames: :mod:`diffbot_sim.world.sdf_frames`.)
What stays here is reading the elements into that graph, ``<state>``, and the bodies it gives.
"""
import os

from diffbot_sim.errors import ModelError
from diffbot_sim.transforms import compose, inverse
from diffbot_sim.world.actor_sdf import read_actor
from diffbot_sim.world.bodies import IDENTITY, Body, WorldDescription
from diffbot_sim.world.model_paths import env_model_paths
from diffbot_sim.world.sdf_elements import ElementReader, sdf_bool, text_of
from diffbot_sim.world.sdf_files import BUILTIN_MODELS, SdfFiles
from diffbot_sim.world.sdf_frames import FrameGraph, Scope, SdfLink, SdfModel

# World children that change nothing our physics does: named once in ``not_simulated``.
_WORLD_NOT_SIMULATED = ("scene", "gui", "atmosphere", "magnetic_field", "spherical_coordinates", "wind",
                        "audio")


def _clean(pose):
    """Plain floats, -0.0 and rounding dust removed, so poses compare and print as the file wrote them."""
    (p, q) = pose

    def tidy(v):
        return 0.0 if abs(v) < 1e-12 else float(v)

    return (tuple(tidy(v) for v in p), tuple(tidy(v) for v in q))


# ------------------------------------------------------------------------------------------ the reader

class _Reader:
    def __init__(self, model_paths, package_model_paths):
        self.files = SdfFiles(model_paths, package_model_paths, self.warn)
        self.values = ElementReader(self.files, self.warn)
        self.world = None
        self.stack = []  # files being included, to catch include cycles
        self.top = []  # the world's models, in order
        self.scope = Scope("", "", None)
        self.frames = FrameGraph(self.warn)  # every frame's world pose
        self.poses = {}  # id(link or model) -> world pose a <state> set

    # -- messages
    def warn(self, message):
        if message not in self.world.warnings:
            self.world.warnings.append(message)

    def skip(self, what):
        if what not in self.world.not_simulated:
            self.world.not_simulated.append(what)

    # -- world
    def read(self, path):
        self.world = WorldDescription(name="", source=path, sdf=True)  # before load(): it may warn already
        root, src = self.files.load(path)
        worlds = root.findall("world")
        if not worlds:
            raise ModelError("no <world> element (is this a model file? spawn models instead)", path, "/sdf")
        world_el = worlds[0]
        name = world_el.get("name") or "default"
        wpath = f"/sdf/world[@name='{name}']"
        self.world.name = name
        if len(worlds) > 1:
            self.warn(f"{path}: {len(worlds)} <world> elements; only the first is read (as Gazebo does)")
        self.stack.append(os.path.abspath(path))
        states = []
        for el in world_el:
            tag = el.tag
            if tag == "model":
                self.add_top(self.model(el, self.scope, src, f"{wpath}/model[@name='{el.get('name')}']"))
            elif tag == "include":
                self.add_top(self.include(el, self.scope, src, f"{wpath}/include"))
            elif tag == "frame":
                self.frame(el, self.scope, src, wpath)
            elif tag == "state":
                states.append(el)
            elif tag == "light":
                self.skip(f"light {el.get('name', '')} ({el.get('type', 'point')})")
            elif tag == "plugin":
                self.skip(f"plugin {el.get('filename', el.get('name', ''))} in world")
            elif tag == "actor":
                self.actor(el, src, f"{wpath}/actor[@name='{el.get('name')}']")
            elif tag in ("road", "population"):
                self.skip(f"{tag} {el.get('name', '')}")
            elif tag in _WORLD_NOT_SIMULATED:
                self.skip(tag)
            elif tag not in ("physics", "gravity"):
                self.warn(f"{path}: {wpath}/{tag}: element not known to SDF worlds; ignored")
        self.physics(world_el, src, wpath)
        if states:
            if len(states) > 1:
                self.warn(f"{path}: {len(states)} <state> blocks; only the first applies (as in Gazebo)")
            self.state(states[0], src, f"{wpath}/state")
        self.emit()
        return self.world

    def add_top(self, model):
        if model is None:
            return
        if model.name in self.scope.models:
            self.warn(f"{model.src.path}: {model.path}: a second model named '{model.name}'; skipped")
            return
        self.scope.models[model.name] = model
        self.top.append(model)

    def physics(self, world_el, src, wpath):
        profiles = world_el.findall("physics")
        chosen = next((p for p in profiles if sdf_bool(p.get("default"))), profiles[0] if profiles else None)
        for other in profiles:
            if other is not chosen:
                self.skip(f"physics profile {other.get('name', '')}")
        gravity_el = world_el.find("gravity")
        if chosen is not None:
            ppath = f"{wpath}/physics"
            kind = chosen.get("type", "ode")
            if kind != "ode":
                self.skip(f"physics type {kind} (Bullet is used whatever the file says)")
            for child in chosen:
                if child.tag == "max_step_size":
                    self.world.max_step_size = self.values.number(chosen, "max_step_size", None, src, ppath, True)
                elif child.tag == "real_time_factor":
                    self.world.real_time_factor = self.values.number(chosen, "real_time_factor", None, src, ppath)
                elif child.tag == "real_time_update_rate":
                    self.world.real_time_update_rate = self.values.number(chosen, "real_time_update_rate", None,
                                                                          src, ppath)
                elif child.tag == "gravity":
                    if src.version >= (1, 6):
                        self.warn(f"{src.path}: {ppath}/gravity: SDF 1.6 moved gravity to <world>; ignored")
                    elif gravity_el is None:
                        gravity_el = child
                elif child.tag == "magnetic_field":
                    self.skip("magnetic_field")
                elif child.tag == "ode":
                    self.ode_settings(child, src, f"{ppath}/ode")
                elif len(child):  # another engine's block (bullet, simbody, dart): name what it sets
                    for grandchild in child:
                        self.skip(f"physics {child.tag}/{grandchild.tag}")
                else:
                    self.skip(f"physics {child.tag}")
        if gravity_el is not None:
            self.world.gravity = self.values.floats(gravity_el.text, 3, src, f"{wpath}/gravity", "<gravity>")

    def ode_settings(self, ode, src, path):
        """``<physics><ode>``: its ``<solver><iters>`` sets Bullet's solver iterations (both solvers iterate over
        the contacts and joints that many times per step); the rest is said in one line, with what Bullet does
        instead."""
        solver = ode.find("solver")
        iters = solver.find("iters") if solver is not None else None
        if iters is not None:
            self.world.solver_iterations = int(self.values.number(solver, "iters", None, src, f"{path}/solver",
                                                                  True))
        rest = [f"{el.tag}/{item.tag} {(item.text or '').strip()}" for el in ode for item in el
                if not (el.tag == "solver" and item.tag == "iters")]
        rest += [f"{el.tag} {(el.text or '').strip()}" for el in ode if not len(el)]
        if rest:
            self.skip("physics ode " + ", ".join(rest) + " (Bullet's sequential-impulse solver with its own "
                      "ERP 0.2, no SOR, no CFM, no contact correction cap; only <solver><iters> is taken)")

    def actor(self, el, src, path):
        """A Gazebo ``<actor>``: read as Gazebo 11 reads it (:mod:`diffbot_sim.world.actor_sdf`); its
        numbers leniently, each oddity one warning."""
        notes = []
        actor = read_actor(el, f"{src.path}: {path}", notes)
        for note in notes:
            self.warn(note)
        if any(a.name == actor.name for a in self.world.actors) or actor.name in self.scope.models:
            self.warn(f"{src.path}: {path}: a second model or actor named '{actor.name}'; skipped")
            return
        self.world.actors.append(actor)

    # -- models
    def include(self, el, parent, src, path):
        uri = text_of(el, "uri")
        if uri is None:
            raise ModelError("<include> has no <uri>", src.path, path)
        path = f"{path}[uri='{uri}']"
        target = self.files.resolve_include(uri, src, path)
        if isinstance(target, tuple):
            root, isrc = self.files.load(f"<built-in {target[1]}>", text=BUILTIN_MODELS[target[1]])
        else:
            if target in self.stack:
                raise ModelError(f"<include> '{uri}' includes itself (through {' -> '.join(self.stack)})",
                                 src.path, path)
            root, isrc = self.files.load(target)
        top = next((c for c in root if c.tag in ("model", "light", "actor", "world")), None)
        name = text_of(el, "name")
        if top is None or top.tag == "world":
            raise ModelError(f"<include> '{uri}': {isrc.path} holds no <model>, <light> or <actor>",
                             src.path, path)
        if top.tag == "light":
            self.skip(f"light {name or top.get('name', '')} ({top.get('type', 'point')})")
            return None
        if top.tag == "actor":
            if name:
                top.set("name", name)
            pose_el = el.find("pose")
            if pose_el is not None:
                for old in top.findall("pose"):
                    top.remove(old)
                top.insert(0, pose_el)
            self.actor(top, isrc, f"{path}/actor[@name='{top.get('name')}']")
            return None
        pose = None
        if el.find("pose") is not None:
            pose = self.values.pose(el.find("pose"), src, f"{path}/pose")
        static = text_of(el, "static")
        self.stack.append(isrc.path)
        try:
            model = self.model(top, parent, isrc, f"/sdf/model[@name='{top.get('name')}']", name=name, pose=pose,
                               static=None if static is None else sdf_bool(static))
        finally:
            self.stack.pop()
        placement = text_of(el, "placement_frame")
        if placement:
            model.placement = placement
        for plugin in el.findall("plugin"):
            self.skip(f"plugin {plugin.get('filename', plugin.get('name', ''))} in model {model.full}")
        return model

    def model(self, el, parent, src, path, name=None, pose=None, static=None):
        own = el.get("name")
        if not own:
            raise ModelError("<model> has no name", src.path, path)
        name = name or own
        full = f"{parent.full}::{name}" if parent.full else name
        model = SdfModel(name, full, parent, src, path)
        model.static = sdf_bool(text_of(el, "static", "false")) if static is None else static
        model.pose, model.relative_to = pose if pose is not None else self.values.child_pose(el, src, path)
        placement = text_of(el, "placement_frame")  # not in the spec, but cheap to honour if written
        if placement:
            model.placement = placement
        for child in el:
            cpath = f"{path}/{child.tag}[@name='{child.get('name', '')}']"
            if child.tag == "link":
                link = self.link(child, model, src, cpath)
                model.links.setdefault(link.name, link)
            elif child.tag == "model":
                self.add_child(model, self.model(child, model, src, cpath))
            elif child.tag == "include":
                self.add_child(model, self.include(child, model, src, f"{path}/include"))
            elif child.tag == "frame":
                self.frame(child, model, src, path)
            elif child.tag == "joint":
                jpose, jrel = self.values.child_pose(child, src, cpath)
                model.joints[child.get("name", "")] = (jpose, jrel, text_of(child, "child", ""))
            elif child.tag == "plugin":
                self.skip(f"plugin {child.get('filename', child.get('name', ''))} in model {full}")
            elif child.tag == "gripper":
                self.skip(f"gripper {child.get('name', '')} in model {full}")
        if model.joints:
            self.warn(f"{src.path}: model {full}: {len(model.joints)} joint(s) "
                      f"({', '.join(sorted(model.joints))}) not simulated; its links are separate bodies")
        return model

    def add_child(self, model, child):
        if child is None:
            return
        if child.name in model.models:
            self.warn(f"{child.src.path}: {child.path}: a second model named '{child.name}' in {model.full}; "
                      f"skipped")
            return
        model.models[child.name] = child

    def frame(self, el, scope, src, path):
        name = el.get("name", "")
        fpath = f"{path}/frame[@name='{name}']"
        pose, rel = self.values.child_pose(el, src, fpath)
        scope.frames[name] = (pose, rel, (el.get("attached_to") or "").strip(), fpath)

    def link(self, el, model, src, path):
        name = el.get("name")
        if not name:
            raise ModelError("<link> has no name", src.path, path)
        link = SdfLink(name, model, src, path)
        link.pose, link.relative_to = self.values.child_pose(el, src, path)
        inertial = el.find("inertial")
        if inertial is not None:
            ipath = f"{path}/inertial"
            link.mass = self.values.number(inertial, "mass", 1.0, src, ipath)  # <= 0: checked once static is known
            link.inertial_pose = self.values.child_pose(inertial, src, ipath)[0]
            tensor = inertial.find("inertia")
            if tensor is not None:
                tpath = f"{ipath}/inertia"
                link.inertia = tuple(self.values.number(tensor, key, default, src, tpath) for key, default in
                                     (("ixx", 1.0), ("iyy", 1.0), ("izz", 1.0), ("ixy", 0.0), ("ixz", 0.0),
                                      ("iyz", 0.0)))
        full = f"{model.full}::{name}"
        if text_of(el, "gravity") is not None and not sdf_bool(text_of(el, "gravity")):
            self.skip(f"gravity off for link {full}")
        if sdf_bool(text_of(el, "kinematic")):
            self.skip(f"kinematic link {full} (simulated as a normal body)")
        for sensor in el.findall("sensor"):
            self.skip(f"sensor {sensor.get('name', '')} ({sensor.get('type', '')}) in link {full}")
        for light in el.findall("light"):
            self.skip(f"light {light.get('name', '')} ({light.get('type', 'point')}) in link {full}")
        for visual in el.findall("visual"):
            link.color = self.values.material(visual, src, f"{path}/visual[@name='{visual.get('name', '')}']")
            if link.color is not None:
                break
        for collision in el.findall("collision"):
            shape = self.values.collision(collision, src, f"{path}/collision[@name='{collision.get('name', '')}']")
            if shape is not None:
                link.shapes.append(shape)
        return link

    # -- state
    def state(self, el, src, path):
        insertions = el.find("insertions")
        if insertions is not None:
            for model_el in insertions.findall("model"):
                mpath = f"{path}/insertions/model[@name='{model_el.get('name')}']"
                self.add_top(self.model(model_el, self.scope, src, mpath))
        deletions = el.find("deletions")
        if deletions is not None:
            for name_el in deletions.findall("name"):
                name = (name_el.text or "").strip()
                if name in self.scope.models:
                    del self.scope.models[name]
                    self.top = [m for m in self.top if m.name != name]
        for model_el in el.findall("model"):
            name = model_el.get("name", "")
            if name not in self.scope.models:
                self.warn(f"{src.path}: {path}/model[@name='{name}']: no model named '{name}' in the world; "
                          f"state entry skipped (as Gazebo does)")
                continue
            self.model_state(self.scope.models[name], model_el, src, f"{path}/model[@name='{name}']")

    def model_state(self, model, el, src, path):
        """Gazebo's Model::SetState: move the model rigidly to the state pose (zero when none is given),
        then put listed links at their own world poses, then nested models likewise."""
        pose_el = el.find("pose")
        target = self.values.pose(pose_el, src, f"{path}/pose")[0] if pose_el is not None else IDENTITY
        scale = text_of(el, "scale")
        if scale is not None and self.values.floats(scale, 3, src, f"{path}/scale", "<scale>") != (1.0, 1.0, 1.0):
            self.warn(f"{src.path}: {path}/scale: model scale {scale} is not simulated; scale 1 used")
        delta = compose(target, inverse(self.current(model)))
        self.move(model, delta)
        for link_el in el.findall("link"):
            lname = link_el.get("name", "")
            link = model.links.get(lname.rsplit("::", 1)[-1])
            if link is None:
                self.warn(f"{src.path}: {path}/link[@name='{lname}']: no link '{lname}' in model {model.full}; "
                          f"skipped")
                continue
            if link_el.find("pose") is not None:
                self.poses[id(link)] = self.values.pose(link_el.find("pose"), src, f"{path}/link/pose")[0]
        for nested_el in el.findall("model"):
            nname = nested_el.get("name", "")
            nested = model.models.get(nname)
            if nested is None:
                self.warn(f"{src.path}: {path}/model[@name='{nname}']: no model '{nname}' in {model.full}; "
                          f"skipped")
                continue
            self.model_state(nested, nested_el, src, f"{path}/model[@name='{nname}']")

    def current(self, node):
        if id(node) in self.poses:
            return self.poses[id(node)]
        if isinstance(node, SdfLink):
            return self.frames.link_pose(node)
        return self.frames.model_pose(node)

    def move(self, model, delta):
        self.poses[id(model)] = compose(delta, self.current(model))
        for link in model.links.values():
            self.poses[id(link)] = compose(delta, self.current(link))
        for nested in model.models.values():
            self.move(nested, delta)

    # -- output
    def emit(self):
        poses = self.poses

        def walk(model, static, top):
            static = static or model.static
            for link in model.links.values():
                placed = self.frames.link_pose(link)
                pose = poses.get(id(link)) or placed
                # The top-level model's frame, moved with the link by a <state> (the model moves rigidly).
                in_model = compose(inverse(self.frames.model_pose(top)), placed)
                if not static and any(s.kind == "plane" for s in link.shapes):
                    self.warn(f"{link.src.path}: {link.path}: a plane in a non-static model is not simulated")
                mass = link.mass
                if not static and mass <= 0:
                    self.warn(f"{link.src.path}: {link.path}/inertial/mass: {mass} is not > 0 in a non-static "
                              f"model; SDF's default 1 kg used")
                    mass = 1.0
                body = Body(name=f"{model.full}::{link.name}", model=model.full, pose=_clean(pose),
                            static=static, shapes=link.shapes, mass=mass, inertia=link.inertia,
                            inertial_pose=_clean(link.inertial_pose), color=link.color,
                            model_pose=_clean(compose(pose, inverse(in_model))))
                for shape in body.shapes:
                    shape.pose = _clean(shape.pose)
                self.world.bodies.append(body)
                if static and any(s.kind == "plane" for s in link.shapes):
                    self.world.has_ground = True
            for nested in model.models.values():
                walk(nested, static, top)

        for model in self.top:
            walk(model, False, model)


def read_world(path, model_paths=None, package_model_paths=None):
    """Read the Gazebo-classic world file ``path``.

    Args:
        path: the ``.world`` (SDF) file.
        model_paths: directories searched for ``model://NAME`` before ``package_model_paths``; None means
            Gazebo's list (``~/.gazebo/models`` then ``GAZEBO_MODEL_PATH``, :func:`env_model_paths`).
        package_model_paths: directories searched after those, e.g. :func:`ros_package_model_paths`.

    Returns:
        a :class:`~diffbot_sim.world.bodies.WorldDescription`: bodies in the order of the file, link-frame world
        poses (after the first ``<state>``), shapes posed in their link frames, mesh paths absolute.

    Raises:
        ModelError: a missing or malformed file (its line named), an include that cannot be resolved (the
            URI, the including file and every directory searched named), a value that is not a number,
            a cycle of frames.
    """
    path = os.path.abspath(path)
    if not os.path.isfile(path):
        raise ModelError("no such file", path)
    reader = _Reader(env_model_paths() if model_paths is None else model_paths, package_model_paths)
    return reader.read(path)
