"""Shadow maps: one depth atlas for every shadowed light, its records, and the pass drawing the
casters into it.

A light casts shadows when its type names a ``shadow_projection`` and its params say
``shadows = true`` (:class:`deferred.interfaces.light.ShadowParams`). Each such light, in scene
order up to the scene's ``max_shadowed_lights``, is given a *slot* and square tiles in the
atlas (a quadtree of power-of-two squares): a spot or point light's as large as the part of the
screen its shadowed region covers asks, at most its ``shadow_resolution`` (``[shadows]
allocation = "coverage"``, :mod:`~deferred.lighting.shadows.coverage`; ``"fixed"``: that
resolution), a directional light's of its ``shadow_resolution``:

- ``cascades`` (directional): ``cascades`` orthographic maps over the camera's depth up to
  ``shadow_distance``, split by the practical split scheme (Zhang et al. 2006, "Parallel-Split
  Shadow Maps", Eq. 3: ``lambda`` between logarithmic and uniform splits). Each cascade bounds
  its slice of the view frustum by a sphere, whose size does not change as the camera turns,
  and its origin is snapped to whole texels, so a moving camera does not make the shadow's
  edges shimmer; lookups blend the last tenth of a cascade into the next.
- ``perspective`` (spot): one map along the cone's axis, wide enough for the outer angle.
- ``cube`` (point): six 90-degree maps (a little wider, so a filter near a face's edge reads
  the face's own texels), chosen by the major axis of the direction from the light.

The light's record carries its slot in ``extra.w`` (the light lists keep a light's index, so
every light path and both pipelines read the slot with the record); the slot's row of the
records (a uniform block sized by ``max_shadowed_lights``) holds its matrices from view space
to the atlas (``lighting/shadows.glsl`` documents the layout). The atlas is one binding source
of the frame, bound to every program that reads it; programs only read it where the scene has
a shadowed light (the define ``SHADOWS``), so a scene without shadows pays nothing.

**Deep opacity maps** (Yuksel and Keyser 2008), where an object's material draws a volume
(``ShadowCaster.opacity_shadows``: fur; in the deferred pipeline ``deferred_opacity`` too): beside
the atlas, two textures over the square of the atlas the lights' maps take (from its corner,
:func:`~deferred.lighting.shadows.opacity.opacity_extent`), at ``opacity_scale`` (a
``[shadows]`` key) of its resolution:
``opacity_first``, the light-view depths of the nearest and the farthest volume fragment each
texel sees (the volume's own front and back, not the depth atlas's casters; min blending of
(depth, -depth); grown by a texel where a texel's centre missed the volume,
``shadows/opacity_front.frag``), and ``opacity``, four layers (RGBA) of the volume's optical
depth (times its density factor) accumulated from that front up to ``OPACITY_LAYERS`` x the
thickest volume's layer (``ShadowCaster.opacity_layer``). Each material's caster draws both
stages (:meth:`~deferred.interfaces.shadow_casting.ShadowCaster.draw_opacity`) and leaves its
translucent part out of the depth atlas (``ShadowView.opacity_maps``): a receiver compiled with
``OPACITY_RECEIVER`` (the volume's own) multiplies a shadowed light by the transmittance at
its depth (``lighting/shadows.glsl``, ``opacity_transmittance``), any other surface by the
transmittance through the whole volume where it lies beyond the volume's back
(``opacity_beyond``). Programs see ``OPACITY_SHADOWS``, so a scene without such a volume
compiles neither lookup.

One module a part: :mod:`~deferred.lighting.shadows.coverage` how large each light's maps are;
:mod:`~deferred.lighting.shadows.plan` the slots and squares of the atlas;
:mod:`~deferred.lighting.shadows.frusta` each map's view and projection (cascades, spot, cube
faces); :mod:`~deferred.lighting.shadows.stagger` which cascades are fitted again each frame
(``[shadows] cascade_updates``: all, or the far ones in turn while the camera moves);
:mod:`~deferred.lighting.shadows.bounds` the boxes and spheres of what objects draw;
:mod:`~deferred.lighting.shadows.opacity` whether and how large the deep opacity maps are;
:mod:`~deferred.lighting.shadows.atlas` the atlas, its records and opacity maps (the binding
source); :mod:`~deferred.lighting.shadows.caster_pass` the pass drawing into them.
"""
