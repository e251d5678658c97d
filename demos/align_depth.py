"""Align a D435i-like depth frame to colour and read keypoint depths, densely and sparsely.

A synthetic 848x480 depth frame (a wall at 4 m, two people at 1.8 m and 2.6 m, 5 % holes) is aligned to a 1280x720
colour camera 1.5 cm to its side, both ways the library offers (librealsense-style rectangles and the paper's point
splat); then the depth of 17 keypoints per person is looked up on the aligned image and, sparsely, straight from the
raw depth frame. Run: python demos/align_depth.py
"""

from collections.abc import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from sid.experiments.bench.runner import RunSettings, measure
from sid.perception.align import Aligner, depth_at_color_pixels
from sid.perception.camera import Calibration, Extrinsics, Intrinsics, deproject, project

# D435i-like streams at the paper's resolutions; depth camera -> colour camera: 1.5 cm right, ~0.3 degree skew.
DEPTH = Intrinsics(848, 480, 426.0, 426.0, 423.5, 239.8)
COLOR = Intrinsics(1280, 720, 910.0, 910.0, 641.2, 358.9)
ROTATION = Rotation.from_euler("xyz", [0.3, -0.2, 0.1], degrees=True).as_matrix()
CALIB = Calibration(COLOR, DEPTH, Extrinsics(ROTATION, np.array([0.015, 0.0, 0.0])))


# Two people as boxes in the depth image: (u0, v0, u1, v1) depth pixels (inclusive) and their distance in metres.
PEOPLE = {"A": ((250, 120, 329, 469), 1.8), "B": ((520, 160, 579, 469), 2.6)}


def synthetic_depth() -> np.ndarray:
    """Depth in metres in the depth camera's grid (0 = no reading): a wall at 4 m and the two people."""
    rng = np.random.default_rng(0)
    depth = np.full((DEPTH.height, DEPTH.width), 4.0) + rng.normal(0, 0.01, (DEPTH.height, DEPTH.width))
    for (u0, v0, u1, v1), z in PEOPLE.values():
        depth[v0 : v1 + 1, u0 : u1 + 1] = z
    depth[rng.random(depth.shape) < 0.05] = 0.0
    return depth.astype(np.float32)


def color_box(box: tuple[int, int, int, int], z: float) -> tuple[float, float, float, float]:
    """A depth-image box at distance z (m), seen in the colour image (the paper's three equations, 2 corners)."""
    corners = deproject(np.array([box[:2], box[2:]], dtype=float), np.array([z, z]), DEPTH)
    (u0, v0), (u1, v1) = project(CALIB.depth_to_color.apply(corners), COLOR)
    return u0, v0, u1, min(v1, COLOR.height - 1.0)


def keypoints_of(box: tuple[float, float, float, float], seed: int) -> np.ndarray:
    """17 colour pixels spread over a person's colour box (u0, v0, u1, v1); three on its silhouette edges."""
    rng = np.random.default_rng(seed)
    u0, v0, u1, v1 = box
    u = rng.uniform(u0, u1, 17)
    u[:3] = (u0, u1, u0)  # on the edge: the patch holds both the person and the wall
    return np.column_stack([u, rng.uniform(v0, v1, 17)])


def median_ms(function: Callable[[], object]) -> float:
    """Median milliseconds of 50 calls after one untimed call (``sid bench``'s timing harness)."""
    return measure(function, RunSettings(warmup=1, min_runs=50, max_runs=50, budget_s=1.0)).median_ms


def main() -> None:
    depth = synthetic_depth()
    rectangle, point = Aligner(CALIB, mode="rectangle"), Aligner(CALIB, mode="point")
    aligned = rectangle(depth)
    print(f"aligned {DEPTH.width}x{DEPTH.height} depth to {COLOR.width}x{COLOR.height} colour")
    print(f"  rectangle splat (default): {np.mean(aligned > 0):.1%} of colour pixels have depth")
    print(f"  point splat (paper):       {np.mean(point(depth) > 0):.1%} (holes from upsampling)")

    boxes = {name: color_box(box, z) for name, (box, z) in PEOPLE.items()}
    registered = Calibration(COLOR)  # the aligned image is registered to colour
    for name, box in boxes.items():
        pixels = keypoints_of(box, seed=ord(name))
        dense = depth_at_color_pixels(aligned, pixels, registered)
        sparse = depth_at_color_pixels(depth, pixels, CALIB)
        found = np.isfinite(sparse)
        print(
            f"person {name} ({PEOPLE[name][1]} m): {found.sum()}/17 keypoints with depth, "
            f"median {np.nanmedian(sparse):.2f} m, "
            f"edge keypoints {np.round(sparse[:3], 2).tolist()} m, "
            f"sparse == dense: {np.allclose(sparse, dense, equal_nan=True, atol=1e-5)}"
        )

    pixels = np.concatenate([keypoints_of(box, seed=i) for i, box in enumerate(boxes.values())] * 2)  # 4 x 17
    print("median time per call on this machine:")
    print(f"  full-frame alignment, rectangle: {median_ms(lambda: rectangle(depth)):.2f} ms")
    print(f"  full-frame alignment, point:     {median_ms(lambda: point(depth)):.2f} ms")
    registered_ms = median_ms(lambda: depth_at_color_pixels(aligned, pixels, registered))
    unregistered_ms = median_ms(lambda: depth_at_color_pixels(depth, pixels, CALIB))
    print(f"  68 keypoints, registered:        {registered_ms:.3f} ms")
    print(f"  68 keypoints, unregistered:      {unregistered_ms:.3f} ms")


if __name__ == "__main__":
    main()
