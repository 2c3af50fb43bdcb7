"""The figures command computes every figure (no stored numbers) into PNG files."""

import matplotlib.image as mpimg
import numpy as np

from rockstudy.figures import FIGURES, make_all


def test_every_figure_is_written_and_not_blank(tmp_path):
    paths = make_all(tmp_path)
    assert sorted(p.name for p in paths) == sorted(FIGURES)
    for path in paths:
        img = mpimg.imread(path)
        assert img.shape[0] > 300 and img.shape[1] > 300
        # a drawn figure has many distinct colours; a blank canvas has one
        assert np.unique(img.reshape(-1, img.shape[-1]), axis=0).shape[0] > 50
