"""A glTF file's images as files the materials read by path: an image beside the file is read
where it is, one in a buffer view or a data URI is written once to the cache folder (named by
its content's hash), and one larger than a texture may be (the GL limit, or more than a share
of the memory budget as a float16 mipmapped texture) is halved until it fits, with a warning
naming it, so a huge texture is never a long stall unannounced."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from deferred.errors import InputError
from deferred.gl.resources import image_texture_bytes
from deferred.io.images import MAX_TEXTURE_SIZE, check_image
from deferred.io.memory import memory_budget
from deferred.scene.gltf.accessors import buffer_view_bytes
from deferred.scene.gltf.document import GltfDocument, decode_data_uri, resolve_uri

MIME_SUFFIXES = {"image/png": ".png", "image/jpeg": ".jpg"}
TEXTURE_BUDGET_SHARE = 8  # one texture may take this fraction of the memory budget


def cache_folder() -> Path:
    """Where extracted and downscaled images are kept: ``$XDG_CACHE_HOME/deferred/gltf`` (or
    ~/.cache), or ``$DEFERRED_CACHE/gltf``."""
    root = os.environ.get("DEFERRED_CACHE")
    if root:
        return Path(root) / "gltf"
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "deferred" / "gltf"


class ImageFiles:
    """The file of each image of a document, made the first time a texture asks for it."""

    def __init__(self, document: GltfDocument):
        self.document = document
        self._paths: dict[int, Path] = {}

    def path(self, index: int, where: str) -> Path:
        """Image ``index`` as a file (``where`` the JSON path referring to it)."""
        if index not in self._paths:
            self.document.entry("images", index, where)
            self._paths[index] = self._made(index)
        return self._paths[index]

    def _made(self, index: int) -> Path:
        document = self.document
        image = document.gltf.images[index]
        where = f"images[{index}]"
        if image.uri is not None and not image.uri.startswith("data:"):
            path = resolve_uri(document, image.uri, "texture file", f"{where}.uri")
            document.sources.append(path)
        else:
            if image.uri is not None:
                mime, data = decode_data_uri(image.uri, f"{where}.uri", document.name)
                mime = mime or image.mimeType
            elif image.bufferView is not None:
                data = bytes(buffer_view_bytes(document, image.bufferView,
                                               f"{where}.bufferView")[0])
                mime = image.mimeType
            else:
                raise document.error("has neither uri nor bufferView", where)
            suffix = MIME_SUFFIXES.get(mime or "")
            if suffix is None:
                raise document.error(f"mimeType {mime!r:.40}: the framework reads image/png and "
                                     "image/jpeg", f"{where}.mimeType")
            path = _cached(data, suffix)
        return self._fitted(path, where)

    def _fitted(self, path: Path, where: str) -> Path:
        """``path``, or a copy halved until it fits a texture (warned)."""
        at = f"{self.document.name}: {where}"
        try:
            width, height, _ = check_image(path, at, max_size=None)
        except InputError as exc:
            raise InputError(exc.message, at) from None
        limit = memory_budget() // TEXTURE_BUDGET_SHARE
        steps = 0
        while max(width >> steps, height >> steps) > MAX_TEXTURE_SIZE or \
                image_texture_bytes(width >> steps, height >> steps) > limit:
            steps += 1
        if steps == 0:
            return path
        size = (max(1, width >> steps), max(1, height >> steps))
        self.document.warn(f"{where} is {width}x{height}, larger than a texture may be "
                           f"(a side of {MAX_TEXTURE_SIZE}, {limit >> 20} MiB): "
                           f"downscaled to {size[0]}x{size[1]}")
        return _downscaled(path, size)


def _cached(data: bytes, suffix: str) -> Path:
    """``data`` written once to the cache folder under its hash."""
    folder = cache_folder()
    path = folder / f"{hashlib.sha256(data).hexdigest()[:32]}{suffix}"
    if not path.is_file() or path.stat().st_size != len(data):
        folder.mkdir(parents=True, exist_ok=True)
        temporary = path.with_name(f".{path.name}.{os.getpid()}")
        temporary.write_bytes(data)
        os.replace(temporary, path)
    return path


def _downscaled(path: Path, size: tuple[int, int]) -> Path:
    """``path`` resized to ``size`` (OpenImageIO), kept in the cache folder."""
    import OpenImageIO as oiio

    key = hashlib.sha256(f"{path.resolve()}:{path.stat().st_mtime_ns}:{size}".encode())
    out = cache_folder() / f"{key.hexdigest()[:32]}{path.suffix.lower()}"
    if out.is_file():
        return out
    source = oiio.ImageBuf(str(path))
    resized = oiio.ImageBufAlgo.resize(source, roi=oiio.ROI(0, size[0], 0, size[1], 0, 1, 0,
                                                            source.nchannels))
    out.parent.mkdir(parents=True, exist_ok=True)
    temporary = out.with_name(f".{out.stem}.{os.getpid()}{out.suffix}")
    if not resized.write(str(temporary)):
        raise InputError(f"cannot write the downscaled texture: {resized.geterror()}", str(out))
    os.replace(temporary, out)
    return out
