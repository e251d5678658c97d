"""One reading rule for the project's JSON / YAML input files."""

from __future__ import annotations

import json
import os
import stat

import pytest

from sid.documents import load_document
from sid.errors import InputError


@pytest.mark.parametrize(("name", "text"), [("a.json", '{"x": 1}'), ("a.yaml", "x: 1"), ("a.scenario", "x: 1")])
def test_json_by_suffix_yaml_otherwise(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    assert load_document(path) == {"x": 1}


@pytest.mark.parametrize(
    ("name", "text", "message"), [("a.json", "x: 1", "not valid JSON"), ("a.yml", "[1", "not valid YAML")]
)
def test_bad_content_names_file_and_format(tmp_path, name, text, message):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ValueError, match=rf"{name}: {message}"):
        load_document(path)


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        ("a.json", '{"robot": 1, "name": "x", "robot": 2}', r"not valid JSON \(duplicate key 'robot'\)"),
        ("a.json", '{"map": {"resolution": 1, "resolution": 2}}', r"not valid JSON \(duplicate key 'resolution'\)"),
        ("a.yaml", "robot: 1\nname: x\nrobot: 2\n", r"not valid YAML \(found duplicate key 'robot' at line 3"),
        (
            "a.yaml",
            "map:\n  resolution: 1\n  resolution: 2\n",
            r"not valid YAML \(found duplicate key 'resolution' at line 3",
        ),
    ],
)
def test_a_key_given_twice_is_refused(tmp_path, name, text, message):
    # The parsers would keep the last value silently (a second `robot:` replacing the first goal).
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ValueError, match=rf"{name}: {message}"):
        load_document(path)


def test_yaml_merge_keys_may_still_be_overridden(tmp_path):
    path = tmp_path / "a.yaml"
    path.write_text("base: &b {x: 1, y: 2}\nother:\n  <<: *b\n  x: 5\n")
    assert load_document(path) == {"base": {"x": 1, "y": 2}, "other": {"x": 5, "y": 2}}


def test_missing_file_names_what_was_expected(tmp_path):
    with pytest.raises(ValueError, match="missing.json: cannot read scenario file"):
        load_document(tmp_path / "missing.json", "scenario file")


# Regression fixtures (issue 15): bytes that are not a text document at all, and nesting deeper than Python parses.
NOT_TEXT = {
    "binary": b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe",
    "latin1": b'{"name": "caf\xe9"}',
    "utf16": "x: 1".encode("utf-16"),
}


@pytest.mark.parametrize("suffix", [".json", ".yaml"])
@pytest.mark.parametrize("kind", NOT_TEXT)
def test_bytes_that_are_not_utf8_name_the_file_and_the_byte(tmp_path, kind, suffix):
    path = tmp_path / f"{kind}{suffix}"
    path.write_bytes(NOT_TEXT[kind])
    with pytest.raises(
        ValueError,
        match=rf"{kind}{suffix}: cannot read map YAML: byte 0x[0-9a-f]{{2}} at offset \d+ "
        r"\(line \d\) is not UTF-8 text",
    ) as error:
        load_document(path, "map YAML")
    assert type(error.value) is InputError  # not UnicodeDecodeError, whose message names no file


@pytest.mark.parametrize(("name", "text"), [("deep.json", "[" * 100_000 + "]" * 100_000),
                                            ("deep.yaml", "[" * 100_000 + "]" * 100_000),
                                            ("deep_maps.yaml", "{a: " * 100_000 + "1" + "}" * 100_000)])  # fmt: skip
def test_nesting_too_deep_to_parse_is_a_named_error(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ValueError, match=rf"{name}: cannot read scenario file: nested too deeply"):
        load_document(path, "scenario file")


@pytest.mark.parametrize("text", ["when: 2001-02-30", "n: !!int 0xZZ", "x: !!float abc"])
def test_yaml_values_python_cannot_build_name_the_file(tmp_path, text):
    path = tmp_path / "odd.yaml"
    path.write_text(text)
    with pytest.raises(ValueError, match="odd.yaml: not valid YAML"):
        load_document(path)


@pytest.mark.parametrize("name", ["bom.json", "bom.yaml"])
def test_a_utf8_byte_order_mark_is_allowed(tmp_path, name):
    path = tmp_path / name
    path.write_bytes(b"\xef\xbb\xbf" + b'{"x": 1}')
    assert load_document(path) == {"x": 1}


@pytest.mark.parametrize("raw", [b"\x00\x00", b"a: [1\nb: 2\n", b"a: b: c"])
def test_yaml_errors_are_one_line(tmp_path, raw):
    path = tmp_path / "map.yaml"
    path.write_bytes(raw)
    with pytest.raises(ValueError, match="map.yaml: not valid YAML") as error:
        load_document(path)
    assert "\n" not in str(error.value) and "<unicode string>" not in str(error.value)


def test_write_atomically_replaces_whole_and_leaves_no_temporary_file(tmp_path):
    from sid.documents import write_atomically

    path = tmp_path / "a.png"
    path.write_bytes(b"old")
    assert write_atomically(path, b"new") == path
    assert path.read_bytes() == b"new" and [p.name for p in tmp_path.iterdir()] == ["a.png"]


def test_write_atomically_into_a_missing_folder_fails_and_writes_nothing(tmp_path):
    from sid.documents import write_atomically

    with pytest.raises(OSError):
        write_atomically(tmp_path / "missing" / "a.png", b"x")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("umask", [0o022, 0o077, 0o002])
def test_write_atomically_gives_the_permissions_of_the_users_umask(tmp_path, umask):
    from sid.documents import write_atomically

    previous = os.umask(umask)
    try:
        write_atomically(tmp_path / "a.png", b"x")
        (tmp_path / "b.txt").write_bytes(b"x")  # what open() gives under the same umask
    finally:
        os.umask(previous)
    assert stat.S_IMODE((tmp_path / "a.png").stat().st_mode) == 0o666 & ~umask
    assert (tmp_path / "a.png").stat().st_mode == (tmp_path / "b.txt").stat().st_mode


def test_plural_counts_one_and_many():
    from sid.documents import plural

    assert [plural(n, "group") for n in (0, 1, 2)] == ["0 groups", "1 group", "2 groups"]
    assert plural(1, "person", "people") == "1 person" and plural(3, "person", "people") == "3 people"


def test_costmap_says_one_group_not_one_groups(tmp_path, capsys):
    from sid.cli import main
    from tests.conftest import REPO_ROOT

    assert main(["costmap", str(REPO_ROOT / "examples" / "conversation.json"), "--out", str(tmp_path)]) == 0
    assert ", 1 group (social)" in capsys.readouterr().out


@pytest.mark.parametrize(
    "character",
    ["\x85", "\u2028", "\u2029", "\n", "\r", "\x0b", "\x0c", "\x1c", "\x1e", "\x9b", "\u200b", "\ufeff", "\U000e0001"],
)
def test_summary_quotes_a_value_on_one_printable_line_whatever_its_characters(character):
    """Line breaks to ``str.splitlines``, a C1 control that drives terminals, invisible format characters: each is
    escaped, and the text still reads back as the value."""
    from sid.documents import summary

    text = summary({f"key{character}": [f"valué{character}"], "other": character})
    assert len(text.splitlines()) == 1 and text.isprintable()
    assert json.loads(text) == {f"key{character}": [f"valué{character}"], "other": character}
    assert "é" in text  # printable characters stay as they are


def test_groups_error_quoting_a_line_separator_is_one_line(tmp_path, capsys):
    from sid.cli import main

    lines = tmp_path / "people.jsonl"
    lines.write_text(json.dumps({"people": [{"id": {"\u2028": 1}, "x": 0.0, "y": 0.0, "theta": 0.0}]}) + "\n")
    main(["groups", str(lines)])
    errors = [line for line in capsys.readouterr().err.splitlines() if "id must be an integer" in line]
    assert len(errors) == 1 and errors[0].endswith('got {"\\u2028": 1}')


def _encoded(kind: str) -> bytes:
    """A 64 x 48 picture as PNG, or as JPEG (baseline, progressive, with restart markers, or with an EXIF thumbnail:
    a whole JPEG inside its header, end marker included)."""
    import io

    import numpy as np
    from PIL import Image

    pixels = np.random.default_rng(0).integers(0, 255, (48, 64, 3), dtype=np.uint8)
    out = io.BytesIO()
    image = Image.fromarray(pixels)
    if kind == "png":
        image.save(out, "PNG")
    elif kind == "thumbnail":
        thumbnail = io.BytesIO()
        Image.fromarray(pixels[:8, :8]).save(thumbnail, "JPEG")
        exif = Image.Exif()
        exif[0x0112] = 1
        image.save(out, "JPEG", exif=exif.tobytes() + thumbnail.getvalue())  # inside the APP1 segment
    else:
        options = {"progressive": kind == "progressive"} | ({"restart_marker_blocks": 1} if kind == "restart" else {})
        image.save(out, "JPEG", quality=95, **options)
    return out.getvalue()


@pytest.mark.parametrize("kind", ["png", "baseline", "progressive", "restart", "thumbnail"])
def test_an_image_cut_short_is_told_from_a_whole_one(kind):
    from sid.documents import image_cut_short

    data = _encoded(kind)
    fmt = "PNG" if kind == "png" else "JPEG"
    assert not image_cut_short(data, fmt)
    assert not image_cut_short(data + b"\0" * 100, fmt)  # bytes after the end, as some writers pad
    for keep in (len(data) - 1, len(data) - 2, len(data) * 3 // 4, len(data) // 2, 30):
        assert image_cut_short(data[:keep], fmt), keep
    assert not image_cut_short(b"P5 1 1 255 x", "PPM")  # the other formats are not checked
