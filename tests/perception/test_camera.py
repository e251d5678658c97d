"""Camera records, pinhole (de)projection and the camera -> world mount transform."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from sid.documents import InputWarning
from sid.errors import InputError
from sid.perception.camera import Calibration, Extrinsics, Intrinsics, deproject, pixel_rays, project
from sid.perception.mount import CameraMount

D435_COLOR = Intrinsics(1280, 720, 910.0, 910.0, 640.0, 360.0)


@given(u=st.floats(0, 1279), v=st.floats(0, 719), z=st.floats(0.2, 10.0))
def test_project_inverts_deproject(u, v, z):
    point = deproject(np.array([[u, v]]), np.array([z]), D435_COLOR)
    assert point[0, 2] == pytest.approx(z)
    np.testing.assert_allclose(project(point, D435_COLOR), [[u, v]], atol=1e-9)


def test_principal_point_lies_on_the_optical_axis():
    np.testing.assert_allclose(deproject([[640.0, 360.0]], [2.0], D435_COLOR), [[0.0, 0.0, 2.0]])


def test_points_behind_the_camera_project_to_nan():
    assert np.isnan(project([[0.0, 0.0, -1.0]], D435_COLOR)).all()


def test_scaled_intrinsics_keep_pixel_centres():
    half = D435_COLOR.scaled(640, 360)
    point = np.array([[0.3, -0.2, 2.0]])
    full_px, half_px = project(point, D435_COLOR), project(point, half)
    np.testing.assert_allclose((half_px + 0.5) * 2 - 0.5, full_px, atol=1e-9)


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("fx", -1.0, "fx must be a positive number of pixels"),
        ("cx", float("nan"), "cx"),
        ("width", 0, "width"),
        ("cx", 1e6, r"cx must be a finite number of pixels in \[0, 1280\], got 1000000.0"),
        ("cy", -1e6, r"cy must be a finite number of pixels in \[0, 720\]"),
        ("fx", 1e308, r"fx must be a finite number of pixels in \[12.8, 128000\]"),
        ("fy", 5e-324, r"fy must be a finite number of pixels in \[7.2, 72000\], got 5e-324"),  # rays of slope inf
    ],
)
def test_bad_intrinsics_are_named(field, value, message):
    data = D435_COLOR.to_dict() | {field: value}
    with pytest.raises(ValueError, match=message):
        Intrinsics.from_dict(data)


def test_extrinsics_reject_non_rotation():
    with pytest.raises(ValueError, match="orthonormal"):
        Extrinsics(np.diag([1.0, 2.0, 1.0]), np.zeros(3))


def test_calibration_json_round_trip(tmp_path):
    angle = 0.02
    rotation = np.array([[np.cos(angle), 0, np.sin(angle)], [0, 1, 0], [-np.sin(angle), 0, np.cos(angle)]])
    calib = Calibration(
        D435_COLOR, Intrinsics(848, 480, 420.0, 420.0, 424.0, 240.0), Extrinsics(rotation, [0.015, 0.0, 0.0]), 0.001
    )
    path = tmp_path / "calib.json"
    path.write_text(json.dumps(calib.to_dict()))
    loaded = Calibration.from_json(path)
    assert loaded.color == calib.color and loaded.depth == calib.depth
    np.testing.assert_allclose(loaded.depth_to_color.rotation, rotation)


def test_flat_intrinsics_json_means_registered_depth(tmp_path):
    path = tmp_path / "intrinsics.json"
    path.write_text(json.dumps({"fx": 525, "fy": 525, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480}))
    calib = Calibration.from_json(path)
    assert calib.depth is None and calib.color.fx == 525


@pytest.mark.parametrize("text", ["not json", "[1, 2]", '{"fx": 1}'])
def test_malformed_calibration_names_the_file(tmp_path, text):
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(ValueError, match="bad.json"):
        Calibration.from_json(path)


def test_level_mount_maps_optical_axes_to_rep103():
    mount = CameraMount(height=0.9)
    # 2 m ahead, 0.5 m to the camera's right, 0.4 m below the optical centre.
    world = mount.camera_to_world([[0.5, 0.4, 2.0]])
    np.testing.assert_allclose(world, [[2.0, -0.5, 0.5]])


@given(tilt=st.floats(-1.2, 1.2), height=st.floats(0.1, 2.0))
def test_mount_round_trip_and_ground_plane(tilt, height):
    mount = CameraMount(height=height, tilt=tilt)
    points = np.array([[0.3, -0.1, 2.0], [-1.0, 0.5, 4.0]])
    np.testing.assert_allclose(mount.world_to_camera(mount.camera_to_world(points)), points, atol=1e-9)
    # The optical axis points down by `tilt`.
    axis = mount.camera_to_world([[0.0, 0.0, 1.0]])[0] - [0.0, 0.0, height]
    assert np.arctan2(-axis[2], axis[0]) == pytest.approx(tilt)


def test_mount_rejects_vertical_tilt():
    with pytest.raises(ValueError, match="tilt"):
        CameraMount(tilt=np.pi / 2)


@pytest.mark.parametrize(("field", "value"), [("height", -5.0), ("height", 1e308), ("x", 1e300), ("y", -11.0)])
def test_mount_rejects_a_camera_below_the_ground_or_off_the_robot(field, value):
    # 1e308 m used to reach the PCA as overflowed coordinates ("Eigenvalues did not converge").
    with pytest.raises(ValueError, match=rf"camera mount: {field} must be a finite number of metres in \["):
        CameraMount(**{field: value})


FLAT = {"width": 640, "height": 480, "fx": 525, "fy": 525, "cx": 319.5, "cy": 239.5}
FULL = {"color": FLAT, "depth": FLAT, "depth_to_color": {"rotation": np.eye(3).tolist(), "translation": [0.01, 0, 0]}}


# Regression fixtures (issue 15): each was a TypeError naming neither the file nor the field.
@pytest.mark.parametrize(
    ("data", "message"),
    [
        (FLAT | {"fx": None}, "intrinsics: fx must be a number, got null"),
        (FLAT | {"fx": [525]}, "intrinsics: fx must be a number, got [525]"),
        (FLAT | {"fx": "525"}, 'intrinsics: fx must be a number, got "525"'),
        (FLAT | {"fx": True}, "intrinsics: fx must be a number, got true"),
        (FLAT | {"width": None}, "intrinsics: width must be a number, got null"),
        (FLAT | {"width": 640.5}, "intrinsics: width must be a whole number of pixels, got 640.5"),
        (FLAT | {"width": 1e300}, "intrinsics: width must be a finite number of pixels in [1, 100000], got 1e+300"),
        (FLAT | {"depth_scale_m": None}, "depth_scale_m must be a number, got null"),
        (FLAT | {"depth_scale_m": [0.001]}, "depth_scale_m must be a number, got [0.001]"),
        (FLAT | {"depth_scale": 0}, "depth_scale must be a finite number of metres per unit in (0, 1], got 0"),
        (FLAT | {"depth_scale": 1e300}, "depth_scale must be a finite number of metres per unit in (0, 1], got 1e+300"),
        (FLAT | {"coeffs": 5}, "intrinsics: coeffs must be a list of numbers, got 5"),
        (FLAT | {"model": 5}, "intrinsics: model must be a distortion model name, got 5"),
        ({"color": "abc"}, 'color: expected an object with width, height, fx, fy, cx, cy, got "abc"'),
        (FULL | {"color": FLAT | {"fy": None}}, "color: fy must be a number, got null"),
        (FULL | {"depth": [1, 2]}, "depth: expected an object with width, height, fx, fy, cx, cy, got [1, 2]"),
        (FULL | {"depth": {}}, "depth: missing field 'width'"),
        (
            FULL | {"depth_to_color": "abc"},
            'depth_to_color: expected an object with rotation and translation, got "abc"',
        ),
        (
            FULL | {"depth_to_color": {"rotation": "abc", "translation": [0, 0, 0]}},
            'depth_to_color: rotation must be a 3x3 row-major matrix of numbers, got "abc"',
        ),
        (
            FULL | {"depth_to_color": {"rotation": np.eye(3).tolist(), "translation": None}},
            "depth_to_color: translation must be [x, y, z] in metres, got null",
        ),
        (
            FULL | {"depth_to_color": {"rotation": np.diag([1, 2, 1]).tolist(), "translation": [0, 0, 0]}},
            "depth_to_color: rotation is not orthonormal",
        ),
        ([FLAT], "expected a JSON object, got [{"),
    ],
)
def test_mistyped_calibration_fields_name_the_file_field_and_value(tmp_path, data, message):
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError) as error:
        Calibration.from_json(path)
    assert type(error.value) is InputError  # sid's own, not a KeyError or a float() error
    assert str(error.value).startswith(f"calibration {path}: ") and message in str(error.value)


@pytest.mark.parametrize("raw", [b"\xff\xfe\x00{", b"\x89PNG\r\n\x1a\n", b"[" * 100_000])
def test_calibration_that_is_not_json_text_names_the_file(tmp_path, raw):
    path = tmp_path / "intrinsics.json"
    path.write_bytes(raw)
    with pytest.raises(ValueError, match="intrinsics.json: (cannot read calibration JSON|not valid JSON)"):
        Calibration.from_json(path)


def test_calibration_values_that_are_right_still_load(tmp_path):
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps(FULL | {"depth_scale_m": 0.0001, "color": FLAT | {"ppx": 1.0} | {"coeffs": [0.1] * 5}}))
    with pytest.warns(InputWarning, match="color: distortion coefficients"):
        calib = Calibration.from_json(path)
    assert calib.depth_scale == 0.0001 and calib.color.coeffs == (0.1,) * 5 and calib.depth is not None


def test_misspelt_depth_section_is_warned_and_its_extrinsics_refused(tmp_path):
    """A misspelt depth section left the depth taken as registered, its non-identity depth_to_color ignored, without
    a word; the unread section is now named, and a calibration without depth intrinsics but with extrinsics is
    refused."""
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps({k: v for k, v in FULL.items() if k != "depth"} | {"depth_intrinsics": FULL["depth"]}))
    with (
        pytest.warns(InputWarning, match=r'fields sid does not read: \["depth_intrinsics"\]'),
        pytest.raises(ValueError, match=f"calibration {path}: depth_to_color is not the identity but there are no"),
    ):
        Calibration.from_json(path)
    with pytest.raises(ValueError, match="no depth intrinsics"):
        Calibration(Intrinsics(640, 480, 600.0, 600.0, 320.0, 240.0), None, Extrinsics(np.eye(3), [0.015, 0, 0]))
    Calibration(Intrinsics(640, 480, 600.0, 600.0, 320.0, 240.0), None, Extrinsics())  # registered: fine


def test_calibration_numbers_sid_does_not_use_are_said(tmp_path, recwarn):
    """A misspelt depth_scale (0.1 mm depth read as millimetres: every depth ten times too far) and distortion sid
    does not apply were accepted without a word; each is now an InputWarning naming the file and the field. Text
    fields (a note) and zero coefficients pass quietly."""
    path = tmp_path / "intrinsics.json"
    path.write_text(json.dumps(FLAT | {"depth_scal": 0.0001, "k1": 0.2, "note": "Kinect", "coeffs": [0.0] * 5}))
    with pytest.warns(InputWarning) as warned:
        calib = Calibration.from_json(path)
    assert calib.depth_scale == 0.001
    assert [str(w.message) for w in warned] == [
        f'calibration {path}: fields sid does not read: ["depth_scal", "k1"] (it reads width, height, fx, fy, cx, cy, '
        "ppx, ppy, model, coeffs, depth_scale, depth_scale_m, depth_aligned_to_color); a misspelt field keeps its "
        "default"
    ]
    path.write_text(json.dumps(FULL | {"color": FLAT | {"model": "brown_conrady", "coeffs": [0.2, -0.5, 0, 0, 0.1]}}))
    with pytest.warns(InputWarning) as warned:
        Calibration.from_json(path)
    assert [str(w.message) for w in warned] == [
        f"calibration {path}: color: distortion coefficients [0.2, -0.5, 0, 0, 0.1] are not applied: sid treats the "
        "camera as an ideal pinhole; undistort the images first"
    ]
    path.write_text(json.dumps(FLAT | {"note": "registered", "depth_aligned_to_color": True, "coeffs": [0] * 5}))
    recwarn.clear()
    Calibration.from_json(path)
    assert not [w for w in recwarn if issubclass(w.category, InputWarning)]


def test_pixel_rays_are_k_inverse_of_the_pixels():
    intr = Intrinsics(640, 480, 525.0, 530.0, 319.5, 239.5)
    pixels = np.array([[0.0, 0.0], [319.5, 239.5], [639.0, 100.0], [-0.5, 479.5]])
    x, y = pixel_rays(pixels[:, 0], pixels[:, 1], intr)
    expected = np.linalg.solve(intr.K, np.c_[pixels, np.ones(4)].T)  # K^-1 [u v 1] = (x, y, 1)
    np.testing.assert_allclose(np.stack([x, y]), expected[:2], rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(deproject(pixels, np.full(4, 2.0), intr)[:, :2], 2.0 * np.stack([x, y], axis=1))
    columns, rows = pixel_rays(np.arange(640), np.arange(480)[:, None], intr)  # each axis on its own
    assert columns.shape == (640,) and rows.shape == (480, 1) and columns[0] == x[0] and rows[0, 0] == y[0]
