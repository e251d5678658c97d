"""A map image larger than the cell limit is refused from its header, before any pixel is decoded (issue 15)."""

from __future__ import annotations

import pytest

from costmap.mapfile import MapFileError, read_map
from sid.checks import Limits, use_limits

META = (
    "image: {image}\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.25\n"
)


def test_image_above_the_limit_is_refused_by_its_header(tmp_path):
    (tmp_path / "m.pgm").write_bytes(b"P5\n40 30\n255\n")  # a header only: decoding would fail
    (tmp_path / "m.yaml").write_text(META.format(image="m.pgm"))
    with (
        use_limits(Limits(map_cells=1000)),
        pytest.raises(MapFileError, match=r"m.yaml: .*m.pgm: map image: 40 x 30 = 1,200 pixels is more than the limit"),
    ):
        read_map(tmp_path / "m.yaml")


def test_image_within_the_limit_reads(tmp_path):
    (tmp_path / "m.pgm").write_bytes(b"P5\n4 3\n255\n" + bytes([0] * 12))
    (tmp_path / "m.yaml").write_text(META.format(image="m.pgm"))
    assert read_map(tmp_path / "m.yaml").data.shape == (3, 4)
