"""Bar charts of the navigation study (OpenCV drawing, BGR uint8): one panel per metric, a pair of bars per planner
(without and with the social layer), the value written over each bar."""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from planner.render import WITH_COLOUR, WITHOUT_COLOUR

FONT = cv2.FONT_HERSHEY_SIMPLEX
TEXT = (40, 40, 40)
GRID = (225, 225, 225)
PANEL_SIZE = (560, 300)  # width, height (px)

# (summary key, panel title, value format)
NAVIGATION_PANELS: tuple[tuple[str, str, str], ...] = (
    ("success_rate", "success rate", ".2f"),
    ("intrusion_rate", "o-space intrusion rate (share of paths entering a zone)", ".2f"),
    ("mean_intrusion_m", "mean o-space intrusion length (m)", ".2f"),
    ("median_min_person_distance_m", "median min distance to a person (m)", ".2f"),
    ("median_length_ratio", "median path length / straight line", ".3f"),
    ("median_planning_time_s", "median planning time (s)", ".2f"),
)


def bar_panel(rows: Sequence[dict], key: str, title: str, fmt: str, size: tuple[int, int] = PANEL_SIZE) -> np.ndarray:
    """One panel: for each planner in ``rows`` (``summarise`` rows), a red bar without and a purple bar with the
    social layer, height ``row[key]`` (missing values are left out)."""
    width, height = size
    img = np.full((height, width, 3), 255, np.uint8)
    cv2.putText(img, title, (12, 22), FONT, 0.5, TEXT, 1, cv2.LINE_AA)
    planners = list(dict.fromkeys(r["planner"] for r in rows))
    values = [r[key] for r in rows if r.get(key) is not None]
    top = (max(values, default=0.0) or 1.0) * 1.18  # all zero: a 0..1 axis
    left, right, y0, y1 = 58, width - 12, 40, height - 34
    for tick in np.linspace(0.0, top / 1.18, 4):
        v = int(round(y1 - (y1 - y0) * tick / top))
        cv2.line(img, (left, v), (right, v), GRID, 1)
        cv2.putText(img, format(tick, ".2f"), (8, v + 4), FONT, 0.38, TEXT, 1, cv2.LINE_AA)
    cv2.line(img, (left, y1), (right, y1), TEXT, 1)
    cv2.line(img, (left, y0), (left, y1), TEXT, 1)
    slot = (right - left) / max(1, len(planners))
    for i, planner in enumerate(planners):
        for j, (social, colour) in enumerate(((False, WITHOUT_COLOUR), (True, WITH_COLOUR))):
            row = next((r for r in rows if r["planner"] == planner and r["social_layer"] == social), None)
            if row is None or row.get(key) is None:
                continue
            x0 = int(left + i * slot + slot * (0.12 + 0.39 * j))
            x1 = int(x0 + slot * 0.36)
            v = int(round(y1 - (y1 - y0) * row[key] / top))
            cv2.rectangle(img, (x0, min(v, y1 - 1)), (x1, y1), colour, -1)
            cv2.putText(img, format(row[key], fmt), (x0, v - 4), FONT, 0.34, TEXT, 1, cv2.LINE_AA)
        label_size = cv2.getTextSize(planner, FONT, 0.4, 1)[0][0]
        cv2.putText(img, planner, (int(left + (i + 0.5) * slot - label_size / 2), y1 + 18), FONT, 0.4, TEXT, 1,
                    cv2.LINE_AA)  # fmt: skip
    return img


def navigation_chart(rows: Sequence[dict], title: str, subtitle: str = "") -> np.ndarray:
    """The study's summary (``navigation.summarise`` rows by planner) as a grid of ``NAVIGATION_PANELS``, with a title,
    a subtitle and a legend."""
    panels = [bar_panel(rows, key, name, fmt) for key, name, fmt in NAVIGATION_PANELS]
    columns = 3
    blank = np.full_like(panels[0], 255)
    while len(panels) % columns:
        panels.append(blank)
    grid = np.vstack([np.hstack(panels[i : i + columns]) for i in range(0, len(panels), columns)])
    header = np.full((78, grid.shape[1], 3), 255, np.uint8)
    cv2.putText(header, title, (12, 28), FONT, 0.7, TEXT, 2, cv2.LINE_AA)
    cv2.putText(header, subtitle, (12, 52), FONT, 0.45, TEXT, 1, cv2.LINE_AA)
    x = 12
    for label, colour in (
        ("without the social layer (LiDAR only)", WITHOUT_COLOUR),
        ("with the social layer", WITH_COLOUR),
    ):
        cv2.rectangle(header, (x, 60), (x + 18, 72), colour, -1)
        cv2.putText(header, label, (x + 26, 71), FONT, 0.45, TEXT, 1, cv2.LINE_AA)
        x += 36 + cv2.getTextSize(label, FONT, 0.45, 1)[0][0]
    return np.vstack([header, grid])
