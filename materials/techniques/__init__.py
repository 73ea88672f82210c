"""Reusable building blocks of materials (passes and data), each from a paper's technique.

- :mod:`.stipple`: stippled G-buffer writes and their obliteration (Revie 2.3.4, 2.4.4)
- :mod:`.shells`: concentric-shell rendering, N offset passes of a mesh (Revie 2.3.1)
- :mod:`.heightfield`: the strand heightfield shells fade against (Revie 2.4.1)

Their GLSL lives in ``shaders/techniques/``.
"""
