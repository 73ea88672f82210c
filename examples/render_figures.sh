#!/usr/bin/env bash
# Render every example scene into docs/figures/ (the images of the README and the site).
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p docs/figures
for scene in examples/*.toml; do
    deferred render "$scene" -o "docs/figures/$(basename "$scene" .toml).png"
done
deferred render -o docs/figures/demo.png --size 960x540
python examples/fur_figures.py
python examples/comb_figures.py  # the demo before and after the comb field
python examples/marschner_figures.py  # the demo and Fig. 2.21 with shading = "marschner"
python examples/taa_figures.py  # taa and --samples 16 on Fig. 2.21 and the demo; the turntable GIF
python examples/self_shadow_figures.py  # fur without and with self-shadowing (deep opacity maps)
python examples/pbr_figures.py  # pbr spheres, roughness by metallic, under the sky and a studio HDR
# Silva et al., curling and clumping fur (the shell_fur material): Figs. 7, 9, 11, 12 (c), Table 1's
# torus and the wet-in-the-wind GIF (examples/shell_fur/README.md)
python examples/shell_fur/figures.py
# Costigan's cartoon hair: X-toon shading (Figs. 4.7-4.10, the depth metric), outlines (4.11-4.13)
# and the tonal art map (4.21-4.22) in docs/figures/cartoon_hair/
python examples/cartoon_hair/figures.py
deferred render examples/cartoon_hair/spiky_head.toml -o docs/figures/cartoon_hair_spiky.png
deferred render examples/cartoon_hair/silhouettes.toml -o docs/figures/cartoon_hair_silhouettes.png
deferred render examples/cartoon_hair/moving_head.toml --frames 48 --fps 24 \
    -o docs/figures/cartoon_hair_moving.gif
deferred render examples/cartoon_hair/anchored_head.toml --frames 48 --fps 24 \
    -o docs/figures/cartoon_hair_anchored.gif
# glTF files (#35): the sample models of ../shared/assets in both pipelines, the helmet with fur on
# its crest, a skinned animation, in docs/figures/gltf/
python examples/gltf/figures.py
# the documentation site's materials gallery: each registered material on the same ball, in
# docs/figures/materials/
python docs/material_figures.py
