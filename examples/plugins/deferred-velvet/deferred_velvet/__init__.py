"""deferred-velvet: an example plugin package for the deferred framework.

It adds, through entry points only:

- the shading model ``velvet`` (:mod:`.shading`): wrapped diffuse plus a grazing sheen, reading
  a G-buffer channel of its own, ``sheen`` (sheen colour and wrap);
- the material ``velvet`` (:mod:`.material`), lit by that model in both pipelines;
- the light type ``rim`` (:mod:`.light`): directional light weighted toward silhouettes;
- the effect ``vignette`` (:mod:`.effect`): a post pass darkening the frame's corners.
"""

from importlib import resources

SHADERS = resources.files(__name__) / "shaders"
