"""What a scene's meshes will be, counted before any is built or parsed: the triangles of a
built-in shape from its arguments, of a file from its header (PLY, OFF, binary STL) or its face
lines (OBJ, ASCII STL), and the memory building them takes, checked against the memory budget
first. The cost model (``deferred.render.cost``) counts the work of a scene from these counts
before its meshes load, so a scene whose meshes alone are too much is refused in a second,
not after the minutes and gigabytes of making them.

A count from a file is a lower bound (an OBJ face of n corners is n - 2 triangles; a format
that does not say cheaply counts 0); once loaded, a mesh is counted exactly.

The scene loader (:class:`deferred.scene.loader.SceneBuilder`) makes every object's material
first (:func:`object_materials`), then, where the file has no problem so far, calls
:func:`weigh_objects`: its ``before_meshes(scene, objects)`` is told of the scene as made so far
(its lights and effects, no objects) and each object as the cost model counts it
(:class:`~deferred.interfaces.work.WorkObject`), and a refusal there is the file's, before any
mesh is built or read. A glTF mesh's nodes are counted once loaded.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from deferred.errors import InputError
from deferred.interfaces import registry
from deferred.interfaces.work import WorkObject
from deferred.io.memory import check_memory
from deferred.scene.builtin_meshes import BUILTIN_PREFIX, builtin_arguments, builtin_triangles
from deferred.scene.scene import Scene

if TYPE_CHECKING:
    from deferred.interfaces.material import Material

# what a scene's loader calls before its meshes load (SceneBuilder's before_meshes)
BeforeMeshes = Callable[[Scene, list[WorkObject]], None]
GLTF_MESH_SUFFIXES = (".gltf", ".glb")

# Peak bytes a triangle takes while a mesh is built (float64 positions, normals, tangent frames
# and their temporaries before the float32 vertex format; measured on built-in shapes of 1M and
# 2M triangles: 413-433 bytes)
BUILD_BYTES_PER_TRIANGLE = 440
# Bytes a built mesh holds a triangle (the float32 vertex format and the indices: 48 on a built-in
# sphere, more where fewer vertices are shared)
HELD_BYTES_PER_TRIANGLE = 64
_CHUNK = 1 << 24
_PLY_FACES = re.compile(rb"^element\s+face\s+(\d+)\s*$", re.MULTILINE)


def mesh_triangles(spec: str, base_dir: Path | None = None) -> int:
    """The triangles the mesh ``spec`` names will have, known without building or parsing it
    (0 where it cannot be told cheaply, or the spec is bad: loading it says why)."""
    if spec.startswith(BUILTIN_PREFIX):
        try:
            shape, arguments = builtin_arguments(spec)
        except InputError:
            return 0
        return builtin_triangles(shape, arguments)
    path = Path(spec)
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    try:
        if not path.is_file():
            return 0
        suffix = path.suffix.lower()
        if suffix == ".ply":
            return _ply_faces(path)
        if suffix == ".off":
            return _off_faces(path)
        if suffix == ".stl":
            return _stl_triangles(path)
        if suffix == ".obj":
            return _lines_starting(path, (b"f ", b"f\t"))
    except OSError:
        return 0
    return 0


def _ply_faces(path: Path) -> int:
    with open(path, "rb") as file:
        header = file.read(1 << 16).split(b"end_header", 1)[0]
    found = _PLY_FACES.search(header)
    return int(found.group(1)) if found else 0


def _off_faces(path: Path) -> int:
    with open(path, "rb") as file:
        lines = [line.split(b"#", 1)[0].split() for line in file.read(1 << 16).splitlines()]
    counts = [fields for fields in lines if fields][:2]
    if not counts:
        return 0
    numbers = counts[0][1:] if counts[0][0].upper().endswith(b"OFF") else counts[0]
    if not numbers and len(counts) > 1:
        numbers = counts[1]
    try:
        return int(numbers[1]) if len(numbers) > 1 else 0
    except ValueError:
        return 0


def _stl_triangles(path: Path) -> int:
    with open(path, "rb") as file:
        start = file.read(84)
    if start.lstrip().startswith(b"solid") and b"facet" in _head(path):
        return _lines_starting(path, (b"facet", b" facet", b"  facet", b"\tfacet"))
    if len(start) < 84:
        return 0
    return int.from_bytes(start[80:84], "little")


def _head(path: Path) -> bytes:
    with open(path, "rb") as file:
        return file.read(1024)


def _lines_starting(path: Path, starts: Iterable[bytes]) -> int:
    """Lines of ``path`` that begin with one of ``starts``, read in chunks."""
    pattern = re.compile(rb"^(?:" + b"|".join(map(re.escape, starts)) + rb")", re.MULTILINE)
    count, carry = 0, b""
    with open(path, "rb") as file:
        while chunk := file.read(_CHUNK):
            text = carry + chunk
            cut = text.rfind(b"\n") + 1  # whole lines only; the rest waits for the next chunk
            count += len(pattern.findall(text, 0, cut))
            carry = text[cut:]
    return count + len(pattern.findall(carry))


def check_mesh_memory(triangles: dict[str, int], where: dict[str, str]) -> None:
    """Refuse meshes whose building needs more than the memory budget: one is built at a time
    (its peak, :data:`BUILD_BYTES_PER_TRIANGLE`) while those built before it are held
    (:data:`HELD_BYTES_PER_TRIANGLE`). ``triangles`` by mesh spec, ``where`` the key of each."""
    total = sum(triangles.values())
    if not total:
        return
    largest = max(triangles, key=triangles.__getitem__)
    peak = triangles[largest] * BUILD_BYTES_PER_TRIANGLE + \
        (total - triangles[largest]) * HELD_BYTES_PER_TRIANGLE
    check_memory(peak, f"building {len(triangles)} mesh{'es' * (len(triangles) > 1)} of "
                       f"{total:,} triangles (the largest {triangles[largest]:,}) needs about "
                       "{}", where[largest], "simplify the meshes, or use fewer")


def object_materials(builder: Any) -> list[tuple[type[Material] | None, Material | None]]:
    """Each ``[[object]]``'s material class and material (None where refused: the problem
    collected by ``builder``, a :class:`~deferred.scene.loader.SceneBuilder`)."""
    made = []
    for index, (obj, bad) in enumerate(builder.tables["object"]):
        material = material_cls = None
        if obj is not None and "material" not in bad:
            where = f"{builder.name}: object[{index}]"
            material_cls = builder.collect(registry.materials.get, obj.material,
                                           f"{where}.material")
            if material_cls is not None and "params" not in bad:
                material = builder.collect(material_cls.from_dict, obj.params,
                                           builder.base_dir, f"{where}.params")
        made.append((material_cls, material))
    return made


def weigh_objects(builder: Any, materials: list[tuple[Any, Material | None]]) -> None:
    """The meshes' triangles counted from their specs, ``builder.before_meshes`` told of each
    object, then the memory of building the meshes checked; raises the refusal. A file with
    problems already is refused anyway: not weighed."""
    if builder.problems:
        return
    counts: dict[str, int] = {}
    wheres: dict[str, str] = {}
    objects = []
    for index, ((obj, _), (_, material)) in enumerate(zip(builder.tables["object"], materials,
                                                          strict=True)):
        if obj is None or material is None or \
                Path(obj.mesh).suffix.lower() in GLTF_MESH_SUFFIXES:
            continue
        where = f"{builder.name}: object[{index}]"
        if obj.mesh not in counts:
            counts[obj.mesh] = mesh_triangles(obj.mesh, builder.base_dir)
            wheres[obj.mesh] = f"{where}.mesh"
        label = obj.name or (obj.mesh.partition("?")[0] if obj.mesh.startswith(BUILTIN_PREFIX)
                             else Path(obj.mesh).name)
        objects.append(WorkObject(material, counts[obj.mesh], label, where, obj.mesh))
    if builder.before_meshes is not None:
        builder.before_meshes(builder.scene, objects)
    check_mesh_memory(counts, wheres)
