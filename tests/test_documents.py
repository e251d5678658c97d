"""One reading rule for the project's JSON / YAML input files."""

from __future__ import annotations

import pytest

from sid.documents import load_document


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


def test_missing_file_names_what_was_expected(tmp_path):
    with pytest.raises(ValueError, match="missing.json: cannot read scenario file"):
        load_document(tmp_path / "missing.json", "scenario file")
