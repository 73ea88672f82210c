"""revie_fur's shells sample the strands twice across their slab, along the view ray
(materials/revie_fur/slab.glsl): strands seen at a slant are less a chain of dashes
(Revie Figure 2.20), and the fur keeps its mean brightness."""


import numpy as np
import pytest
from locations import ROOT

from deferred.scene.loader import load_scene


@pytest.mark.slow
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_fig2_20_strands_are_fewer_dashes(render, pipeline):
    result, _ = render(load_scene(ROOT / "examples" / "fig2_20_shells.toml"), pipeline)
    grey = result.image[80:280, 140:340, :3].astype(np.float64) @ np.array([0.299, 0.587,
                                                                               0.114])
    blurred = sum(grey[1 + dy:grey.shape[0] - 1 + dy, 1 + dx:grey.shape[1] - 1 + dx]
                  for dy in (-1, 0, 1) for dx in (-1, 0, 1)) / 9.0
    detail = float(np.abs(grey[1:-1, 1:-1] - blurred).mean())
    print(f"{pipeline}: high-frequency detail {detail:.2f} (7.45 with one sample a shell), "
          f"mean {grey.mean():.1f} (147.6)")
    assert detail < 6.9
    assert abs(grey.mean() - 147.6) < 0.02 * 147.6
