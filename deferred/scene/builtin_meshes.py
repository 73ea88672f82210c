"""The built-in meshes (``builtin:sphere``, ``builtin:torus``, ``builtin:plane``,
``builtin:cube``, ``builtin:head``) and their parameters as a query
(``builtin:torus?segments=78&sides=60``), each checked before the shape is built."""
from __future__ import annotations

import inspect
import math

import numpy as np

from deferred.errors import InputError
from deferred.gl.meshes import MeshData
from deferred.scene.geometry import MAX_TRIANGLES, build_mesh

BUILTIN_PREFIX = "builtin:"
BUILTIN_MESHES = ("sphere", "torus", "plane", "cube", "head")


def _grid_indices(rows: int, cols: int) -> np.ndarray:
    """Two triangles per cell of a (rows+1) x (cols+1) vertex grid, counter-clockwise."""
    r, c = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    a = (r * (cols + 1) + c).ravel()
    b = a + 1
    d = a + cols + 1
    e = d + 1
    return np.concatenate([np.stack([a, d, b], 1), np.stack([b, d, e], 1)])


def builtin_sphere(segments: int = 64, rings: int = 32, radius: float = 1.0) -> MeshData:
    u = np.linspace(0.0, 1.0, segments + 1)
    v = np.linspace(0.0, 1.0, rings + 1)
    vv, uu = np.meshgrid(v, u, indexing="ij")
    theta = vv * math.pi  # from +Y down
    phi = uu * 2.0 * math.pi
    normals = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta),
                        np.sin(theta) * np.cos(phi)], -1).reshape(-1, 3)
    uvs = np.stack([uu, 1.0 - vv], -1).reshape(-1, 2)
    indices = _grid_indices(rings, segments)
    return build_mesh("builtin:sphere", normals * radius, indices, normals, uvs)


def builtin_torus(segments: int = 64, sides: int = 32, major: float = 0.7,
                  minor: float = 0.3) -> MeshData:
    u = np.linspace(0.0, 1.0, segments + 1)
    v = np.linspace(0.0, 1.0, sides + 1)
    vv, uu = np.meshgrid(v, u, indexing="ij")
    phi = uu * 2.0 * math.pi  # around the major circle (Y axis)
    theta = vv * 2.0 * math.pi  # around the tube
    centre = np.stack([np.sin(phi) * major, np.zeros_like(phi), np.cos(phi) * major], -1)
    normal = np.stack([np.sin(phi) * np.cos(theta), np.sin(theta), np.cos(phi) * np.cos(theta)], -1)
    positions = (centre + normal * minor).reshape(-1, 3)
    uvs = np.stack([uu, vv], -1).reshape(-1, 2)
    indices = _grid_indices(sides, segments)[:, [0, 2, 1]]  # counter-clockwise seen from outside
    return build_mesh("builtin:torus", positions, indices, normal.reshape(-1, 3), uvs)


def builtin_plane(divisions: int = 32, size: float = 2.0) -> MeshData:
    """A square in the XZ plane facing +Y, ``size`` wide, centred on the origin."""
    t = np.linspace(-0.5, 0.5, divisions + 1) * size
    zz, xx = np.meshgrid(t, t, indexing="ij")
    positions = np.stack([xx, np.zeros_like(xx), zz], -1).reshape(-1, 3)
    normals = np.tile([0.0, 1.0, 0.0], (len(positions), 1))
    uvs = np.stack([xx / size + 0.5, 0.5 - zz / size], -1).reshape(-1, 2)
    indices = _grid_indices(divisions, divisions)
    return build_mesh("builtin:plane", positions, indices, normals, uvs)


def builtin_cube(size: float = 1.5) -> MeshData:
    positions, normals, uvs, indices = [], [], [], []
    h = size / 2.0
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = np.zeros(3)
            n[axis] = sign
            u_axis = np.zeros(3)
            u_axis[(axis + 1) % 3] = 1.0
            v_axis = np.cross(n, u_axis)
            base = len(positions)
            for cu, cv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                positions.append(n * h + (cu * 2 - 1) * h * u_axis + (cv * 2 - 1) * h * v_axis)
                normals.append(n)
                uvs.append((cu, cv))
            indices += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    return build_mesh("builtin:cube", np.array(positions), np.array(indices),
                      np.array(normals), np.array(uvs, dtype=np.float64))


# builtin:head, in units of the cranium radius: the union of these spheres (x, y, z, radius):
# cranium, face, chin; +y up, +z the face. They are also its collision shape for hair
# (Costigan 4.1, appendix Fig. 1: a head as a group of spheres).
HEAD_SPHERES = np.array([[0.0, 0.0, 0.0, 1.0], [0.0, -0.38, 0.22, 0.8],
                         [0.0, -0.72, 0.34, 0.52]])
_HEAD_CENTRE = np.array([0.0, -0.3, 0.12])  # inside every sphere: the surface is radial from it
_HEAD_BLEND = 40.0  # sharpness of the smooth union (creases rounded by at most log(3)/40)


def builtin_head_spheres(radius: float = 0.1) -> np.ndarray:
    """``builtin:head``'s collision spheres ``(3, 4)`` (centre, radius) for a cranium
    ``radius``: the mesh lies on or just outside their union."""
    return HEAD_SPHERES * radius


def builtin_head(segments: int = 64, rings: int = 48, radius: float = 0.1) -> MeshData:
    """A head, 0.1 m cranium radius by default (about 0.22 m tall): the smooth union of
    :data:`HEAD_SPHERES`, facing +z. Its vertex colours paint the scalp: alpha (the fur length
    scale) 1 on the cranium above a hairline that runs from the forehead down to the nape, 0 on
    the face; RGB comb the hair down and back."""
    u = np.linspace(0.0, 1.0, segments + 1)
    v = np.linspace(0.0, 1.0, rings + 1)
    vv, uu = np.meshgrid(v, u, indexing="ij")
    theta, phi = vv * math.pi, uu * 2.0 * math.pi
    d = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta),
                  np.sin(theta) * np.cos(phi)], -1).reshape(-1, 3)
    # each sphere's exit distance along d from the centre, and their smooth maximum
    rel = HEAD_SPHERES[:, :3] - _HEAD_CENTRE
    b = d @ rel.T
    root = np.sqrt(b * b - (rel ** 2).sum(1) + HEAD_SPHERES[:, 3] ** 2)
    exits = b + root
    weight = np.exp(_HEAD_BLEND * (exits - exits.max(1, keepdims=True)))
    r = exits.max(1) + np.log(weight.sum(1)) / _HEAD_BLEND
    weight /= weight.sum(1, keepdims=True)
    positions = _HEAD_CENTRE + d * r[:, None]
    # the normal of a radial surface r(d) d is d - grad_s(r) / r (grad on the unit sphere)
    grad = ((weight * exits / root)[:, :, None] * rel[None]).sum(1)
    grad -= (grad * d).sum(1, keepdims=True) * d
    normals = d - grad / r[:, None]
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    hairline = 0.05 + 0.45 * positions[:, 2]
    scalp = np.clip((positions[:, 1] - hairline) / 0.15 + 0.5, 0.0, 1.0) * weight[:, 0]
    scalp = np.where(scalp > 0.5, 1.0, 0.0)
    comb = np.tile(np.array([0.5, 0.5 - 0.5 * 0.894, 0.5 - 0.5 * 0.447]), (len(d), 1))
    uvs = np.stack([uu, 1.0 - vv], -1).reshape(-1, 2)
    return build_mesh("builtin:head", positions * radius, _grid_indices(rings, segments),
                      normals, uvs, colors=np.hstack([comb, scalp[:, None]]))


BUILTIN_SHAPES = {"sphere": builtin_sphere, "torus": builtin_torus, "plane": builtin_plane,
             "cube": builtin_cube, "head": builtin_head}




# Bounds of the built-in shapes' integer arguments (subdivision counts); float arguments
# (sizes, radii) must be finite and positive.
BUILTIN_COUNT_RANGE = (3, 4096)
BUILTIN_SIZE_MAX = 1e4
# Triangles each shape makes from its arguments (with defaults): checked before it is built.
_BUILTIN_TRIANGLES = {
    "sphere": lambda a: 2 * a["segments"] * a["rings"],
    "torus": lambda a: 2 * a["segments"] * a["sides"],
    "plane": lambda a: 2 * a["divisions"] ** 2,
    "head": lambda a: 2 * a["segments"] * a["rings"],
    "cube": lambda a: 12,
}


def builtin_triangles(shape: str, arguments: dict[str, int | float]) -> int:
    """The triangles ``builtin:<shape>`` makes with ``arguments`` (its defaults for the rest),
    counted without building it."""
    parameters = inspect.signature(BUILTIN_SHAPES[shape], eval_str=True).parameters
    return _BUILTIN_TRIANGLES[shape]({name: p.default for name, p in parameters.items()}
                                     | arguments)


def builtin_arguments(spec: str, where: str | None = None) -> tuple[str, dict[str, int | float]]:
    """``builtin:torus?segments=78&sides=60`` -> ``("torus", {"segments": 78, "sides": 60})``.

    The arguments are keyword arguments of the shape's function (``builtin_torus``...), each
    parsed as its annotation says (int or float); an unknown shape or key, a bad number or a
    value out of range is an ``InputError`` naming ``where`` (default: the spec).
    """
    where = where or spec
    shape, _, query = spec.removeprefix(BUILTIN_PREFIX).partition("?")
    if shape not in BUILTIN_SHAPES:
        raise InputError(f"unknown built-in mesh '{BUILTIN_PREFIX}{shape}' (choose from "
                         f"{', '.join(BUILTIN_PREFIX + n for n in BUILTIN_MESHES)})", where)
    parameters = inspect.signature(BUILTIN_SHAPES[shape], eval_str=True).parameters
    kinds = {name: parameter.annotation for name, parameter in parameters.items()}
    arguments: dict[str, int | float] = {}
    for item in filter(None, query.split("&")):
        key, equals, text = (part.strip() for part in item.partition("="))
        if key not in kinds:
            raise InputError(f"builtin:{shape} has no parameter '{key}' (parameters: "
                             f"{', '.join(kinds)})", where)
        if not equals or not text:
            raise InputError(f"builtin:{shape} parameter '{key}' has no value "
                             f"(write {key}=NUMBER)", where)
        if key in arguments:
            raise InputError(f"builtin:{shape} parameter '{key}' is given twice", where)
        arguments[key] = _builtin_argument(shape, key, text, kinds[key], where)
    if shape in _BUILTIN_TRIANGLES:
        triangles = builtin_triangles(shape, arguments)
        if triangles > MAX_TRIANGLES:
            raise InputError(f"builtin:{shape} with these arguments has {triangles:,} "
                             f"triangles, more than the {MAX_TRIANGLES:,} a mesh may have",
                             where)
    return shape, arguments


def _builtin_argument(shape: str, key: str, text: str, kind: type, where: str) -> int | float:
    if kind is int:
        try:
            value = int(text)
        except ValueError:
            raise InputError(f"builtin:{shape} parameter '{key}' must be an integer, got "
                             f"'{text}'", where) from None
        low, high = BUILTIN_COUNT_RANGE
        if not low <= value <= high:
            raise InputError(f"builtin:{shape} parameter '{key}' must be {low}..{high}, got "
                             f"{value}", where)
        return value
    try:
        number = float(text)
    except ValueError:
        raise InputError(f"builtin:{shape} parameter '{key}' must be a number, got '{text}'",
                         where) from None
    if not math.isfinite(number) or not 0.0 < number <= BUILTIN_SIZE_MAX:
        raise InputError(f"builtin:{shape} parameter '{key}' must be greater than 0 and at "
                         f"most {BUILTIN_SIZE_MAX:g}, got {text}", where)
    return number
