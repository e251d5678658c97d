"""Bar charts of with/without summaries: every slot drawn inside its panel, values missing or not."""

from __future__ import annotations

import warnings
from pathlib import Path

import matplotlib.image
import pytest
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from sid.experiments.charts import Panel, _draw_panel, bar_chart, from_key


def _rows(value: float | None) -> list[dict]:
    return [{"planner": name, "social_layer": social, "rate": value} for name in ("grid", "rrt") for social in (0, 1)]


@pytest.mark.parametrize("value", [None, 0.5])
def test_n_a_labels_and_bars_stand_inside_their_panel(value: float | None) -> None:
    """Before, a panel without bars kept matplotlib's default x-limits (0..1): its "n/a" labels stood outside it,
    over the neighbouring panel, and the constrained layout collapsed."""
    ax = Figure().subplots()
    _draw_panel(ax, _rows(value), Panel("rate", from_key("rate")))
    low, high = ax.get_xlim()
    labels = [t for t in ax.texts if t.get_text() == "n/a"]
    assert len(labels) == (4 if value is None else 0)
    assert all(low < t.get_position()[0] < high for t in labels)
    bars = [bar for bar in ax.patches if isinstance(bar, Rectangle)]
    assert len(bars) == (0 if value is None else 4)
    assert all(low < bar.get_x() and bar.get_x() + bar.get_width() < high for bar in bars)


def test_a_chart_with_a_panel_of_missing_values_is_written_without_warnings(tmp_path: Path) -> None:
    panels = (Panel("rate", from_key("rate")), Panel("missing", lambda row: None), Panel("half", from_key("rate")))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        path = bar_chart(_rows(0.5), panels, tmp_path / "chart.png", "title")
    height, width = matplotlib.image.imread(path).shape[:2]
    # 5.2 in per column, 1 + 3.6 in tall, at 100 dpi: 459 or 460 rows as matplotlib's version rounds 4.6 x 100
    assert width == 1560 and height in (459, 460)
