#!/bin/sh
# Re-run the sweeps whose results benchmarks/README.md reports, with the commands it gives
# (about 30 minutes on two cores: naive forward with 1024 lights is the slow part).
# Run from the repository root with the package installed with its plot extra
# (`pip install -e '.[plot]'`: the --plot images need matplotlib).
set -e
out=benchmarks/results

# Lights alone: standard materials, forward vs deferred over the number of point lights.
deferred bench benchmarks/lights.toml --size 640x360 --runs 5 --light-paths volumes,naive \
    --lights 0,1,2,4,8,16,64,256,1024 \
    --json $out/lights-640x360.json --csv $out/lights-640x360.csv --plot $out/lights-640x360.png
deferred bench benchmarks/lights.toml --size 1280x720 --runs 3 --light-paths volumes,naive \
    --lights 0,1,2,4,16,64,256 \
    --json $out/lights-1280x720.json --csv $out/lights-1280x720.csv --plot $out/lights-1280x720.png

# Light paths: every path of both pipelines, on lights.toml and on the overdraw scene.
deferred bench benchmarks/lights.toml --size 640x360 --runs 7 --warmup 1 --lights 1,16,256,1024 \
    --json $out/paths-640x360.json --csv $out/paths-640x360.csv --plot $out/paths-640x360.png
deferred bench benchmarks/lights.toml --size 1280x720 --runs 3 --warmup 1 --lights 1,16,256,1024 \
    --json $out/paths-1280x720.json --csv $out/paths-1280x720.csv --plot $out/paths-1280x720.png
deferred bench builtin:overdraw --size 640x360 --runs 3 --warmup 1 --lights 1,16,256 \
    --json $out/overdraw-640x360.json --csv $out/overdraw-640x360.csv \
    --plot $out/overdraw-640x360.png

# Fur shells: the built-in demo scene (Revie's fur on a torus and a sphere, 4 scene lights, SSAO).
deferred bench --size 640x360 --runs 2 --warmup 1 --light-paths tiled,naive \
    --lights 0,16,64 --shells 0,16,64 \
    --json $out/shells-640x360.json --csv $out/shells-640x360.csv --plot $out/shells-640x360.png

# The framework's CPU time per draw call (scenes of 25, 100, 400 cubes; a minute).
python benchmarks/draw_overhead.py
