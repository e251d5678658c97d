"""Bar charts of with/without summaries (matplotlib, Agg backend, written to PNG): one panel per metric, a pair of
bars per planner (without the social layer red, with it purple, as on the costmap pictures), the value over each
bar, a legend above the panels."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from sid.experiments.path_render import WITH_COLOUR, WITHOUT_COLOUR

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["MODE_STYLE", "NAVIGATION_PANELS", "PLANNER_PANELS", "Panel", "bar_chart", "from_key"]


@dataclass(frozen=True)
class Panel:
    """One panel: its title (with the unit) and how to read its value from a ``harness.summarise`` row."""

    title: str
    value: Callable[[dict], float | None]
    fmt: str = ".2f"


def from_key(key: str) -> Callable[[dict], float | None]:
    """A panel value that is the row's ``key``."""
    return lambda row: row[key]


NAVIGATION_PANELS = (
    Panel("success rate", from_key("success_rate")),
    Panel("o-space intrusion rate (share of paths entering a zone)", from_key("intrusion_rate")),
    Panel("mean o-space intrusion length (m)", from_key("mean_intrusion_m")),
    Panel("median min distance to a person (m)", from_key("median_min_person_distance_m")),
    Panel("median path length / straight line", from_key("median_length_ratio"), ".3f"),
    Panel("median planning time (s)", from_key("median_planning_time_s")),
)
"""``sid reproduce navigation``'s chart."""

PLANNER_PANELS = (
    Panel("median planning time (s)", from_key("median_planning_time_s")),
    Panel(
        "median cost above the grid reference (%)",
        lambda row: None if row["median_cost_ratio"] is None else 100 * (row["median_cost_ratio"] - 1),
        ".1f",
    ),
    Panel("median path length in group zones (m)", from_key("median_intrusion_m")),
)
"""``sid compare``'s chart."""

MODE_STYLE = {
    False: ("without the social layer (map + LiDAR)", WITHOUT_COLOUR),
    True: ("with the social layer", WITH_COLOUR),
}


def _rgb(bgr: tuple[int, int, int]) -> tuple[float, float, float]:
    return (bgr[2] / 255, bgr[1] / 255, bgr[0] / 255)


def _label(value: float, fmt: str) -> str:
    text = format(value, fmt)
    return format(0.0, fmt) if float(text) == 0 else text  # no "-0.0"


def _draw_panel(ax: Axes, rows: Sequence[dict], panel: Panel) -> None:
    planners = list(dict.fromkeys(r["planner"] for r in rows))
    width = 0.4
    values, missing = [], []
    for j, (social, (label, colour)) in enumerate(MODE_STYLE.items()):
        xs, heights = [], []
        for i, planner in enumerate(planners):
            row = next((r for r in rows if r["planner"] == planner and r["social_layer"] == social), None)
            x = i + (j - 0.5) * width * 1.05
            value = None if row is None else panel.value(row)
            if value is None:
                missing.append(x)
            else:
                xs.append(x)
                heights.append(value)
        values += heights
        bars = ax.bar(xs, heights, width, color=_rgb(colour), label=label)
        ax.bar_label(bars, labels=[_label(v, panel.fmt) for v in heights], padding=2, fontsize=8)
    low, high = min(values, default=0.0), max(values, default=0.0)
    if high <= 0 and low >= 0:
        ax.set_ylim(0.0, 1.0)  # all zero: a 0..1 axis, so the ticks still read as values
    else:
        span = high - min(low, 0.0)
        ax.set_ylim(min(low, 0.0) - (0.1 * span if low < 0 else 0.0), max(high, 0.0) + 0.15 * span)
    for x in missing:
        ax.text(x, 0.0, "n/a", ha="center", va="bottom", fontsize=8, color="0.45")
        ax.update_datalim([(x - width / 2, 0.0), (x + width / 2, 0.0)])  # its slot, as a bar's, inside the x-limits
    ax.autoscale_view(scaley=False)
    ax.axhline(0.0, color="0.2", linewidth=0.8)
    ax.set_xticks(range(len(planners)), [p.replace("_", "\n") for p in planners])
    ax.set_title(panel.title, loc="left", fontsize=10)
    ax.grid(axis="y", color="0.9")
    ax.set_axisbelow(True)
    ax.spines[["top", "right"]].set_visible(False)


def bar_chart(
    rows: Sequence[dict], panels: Sequence[Panel], path: str | Path, title: str, subtitle: str = "", columns: int = 3
) -> Path:
    """Write ``rows`` (``harness.summarise`` rows by planner, one costmap mode each) as a grid of ``panels`` to a
    PNG at ``path``; returns the path. A missing value (no successful run, or no ratio) is marked "n/a"."""
    # matplotlib loads here, not at import: the CLI imports this module for every command (about 1 s).
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    lines = -(-len(panels) // columns)
    header_in, panel_in = 1.0, 3.6
    fig = Figure(figsize=(5.2 * columns, header_in + panel_in * lines), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(2, 1, height_ratios=[header_in, panel_in * lines])
    head, body = fig.add_subfigure(grid[0]), fig.add_subfigure(grid[1])
    axes = body.subplots(lines, columns, squeeze=False).ravel()
    for ax, panel in zip(axes, panels, strict=False):
        _draw_panel(ax, rows, panel)
    for ax in axes[len(panels) :]:
        ax.set_visible(False)
    head.text(0.01, 0.92, title, fontsize=14, fontweight="bold", va="top")
    head.text(0.01, 0.52, subtitle, fontsize=10, va="top")
    handles, labels = axes[0].get_legend_handles_labels()
    head.legend(handles, labels, loc="lower left", bbox_to_anchor=(0.0, -0.05), ncols=2, frameon=False)
    path = Path(path)
    fig.savefig(path)
    return path
