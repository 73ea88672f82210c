"""Reusable building blocks of materials (passes and data), each from a paper's technique.

- :mod:`.fur`: the shared fur technique: parameters, density, level of detail, root shell and
  self-shadowing (Lengyel et al. 2001; Revie 2.3.1; Silva et al.'s shadow factor)
- :mod:`.fur_shadow`: the fur's shadow caster: its depth pushed a strand away from the light,
  its volume in the deep opacity maps
- :mod:`.fur_volume`: the mip-mapped volume of tapered strands the shells and fins sample
- :mod:`.heightfield`: a strand heightfield image as a fur volume (Revie 2.4.1)
- :mod:`.comb_field`: per-vertex comb directions smoothed over the mesh, crowns at the
  singular points (Revie 2.3.1, 2.4.1)
- :mod:`.shells`: concentric shells, n offset draws of a mesh (Revie 2.3.1)
- :mod:`.fins`: fins at silhouette edges from a geometry shader (Lengyel et al. 2001)
- :mod:`.stipple`: stippled G-buffer writes and their obliteration, and the ``Stipple``
  technique giving both (Revie 2.3.4, 2.4.4)
- :mod:`.fur_light`: the fur's light gathered once a frame from the light accumulation, and
  the ``FurLight`` input reading it (Revie 2.4.4, Listing 2.2)
- :mod:`.strands`: one-particle mass-spring strands and their curl (Silva et al. 3.2.1, Eq. 2-4)
- :mod:`.wetness`: the wetness mask of droplets and clumps (Silva et al. 3.1, Algorithm 1);
  :mod:`.uv_seams`: a mesh's UV charts, and droplets carried across the seams between them
- :mod:`.topology`: vertices welded by position across UV seams (fins, strands, clumps)
- :mod:`.hair_strands`, :mod:`.hair_dynamics`, :mod:`.hair_tubes`: cartoon hair's guide strands
  (files, scalp, styles, Catmull-Rom), tetrahedral mass-spring dynamics and tube meshes
  (Costigan 4.1-4.3.2)
- :mod:`.xtoon`: X-toon 2D ramps for the toon shading model: depth, backlight and specular
  metrics (Costigan 4.3.3-4.3.6, after Barla et al.)
- :mod:`.tam`: tonal art maps generated from a stroke (Costigan 2.4.3, 4.3.8, after Praun et
  al.); :mod:`.hatching`: the maps cached on disk, their tone blend and texture

Their GLSL lives beside them, in this folder.
"""
