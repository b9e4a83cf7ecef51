import pytest
import yaml

from emopose.joint_limits import LibraryError
from tests.conftest import REST, load_library, make_library_dir, write_motion


def test_guide_version_bumps_on_save_and_new_variant_resolves(writable_library):
    version = writable_library.version
    data = {"name": "my_new_wave", "class": "welcoming", "description": "a new wave",
            "keyframes": [REST, [v + 0.2 for v in REST], REST]}
    writable_library.save(data)
    assert writable_library.version == version + 1 and writable_library.get("my_new_wave").cls == "welcoming"


def test_save_is_atomic_and_keeps_a_backup(writable_library):
    data = {"name": "agreeing_a", "class": "agreeing", "description": "edited", "keyframes": [REST] * 3}
    writable_library.save(data)
    folder = writable_library.write_dir
    assert yaml.safe_load((folder / "agreeing_a.yaml").read_text())["description"] == "edited"
    assert list((folder / ".backup").glob("agreeing_a.v*.yaml"))
    assert not list(folder.glob(".*.tmp"))


@pytest.mark.parametrize("mutation,needle", [
    (lambda d: d.update(keyframes=[REST[:13]] * 3), "keyframe 0 has 13 values"),
    (lambda d: d.update(keyframes=[REST] * 2), "3..14 keyframes"),
    (lambda d: d.update({"class": "dancing"}), "class"),
    (lambda d: d.update(keyframes=[REST, [9.0] * 14, REST]), "leave the joint limits"),
    (lambda d: d.update(extra_field=1), "extra_field"),
])
def test_broken_file_names_file_entry_and_field(tmp_path, mutation, needle):
    folder = make_library_dir(tmp_path / "lib")
    data = {"name": "broken_one", "class": "agreeing", "description": "broken", "keyframes": [REST] * 3}
    mutation(data)
    write_motion(folder, "broken_one", data.pop("class"), data.pop("keyframes"),
                 **{k: v for k, v in data.items() if k not in ("name", "description")})
    with pytest.raises(LibraryError) as info:
        load_library(folder)
    assert "broken_one.yaml" in str(info.value) and needle in str(info.value)


def test_unreadable_yaml_and_duplicate_names(tmp_path):
    folder = make_library_dir(tmp_path / "lib")
    (folder / "zz.yaml").write_text("name: [unclosed")
    with pytest.raises(LibraryError, match="zz.yaml: not readable YAML"):
        load_library(folder)
    (folder / "zz.yaml").write_text((folder / "agreeing_a.yaml").read_text())
    with pytest.raises(LibraryError, match="already defined"):
        load_library(folder)


def test_duration_rule(library):
    assert library.get("agreeing_a").default_duration == 1.0  # clip(0.3 * 3, 1, 5)
    assert library.get("agreeing_b").default_duration == 1.5  # explicit


@pytest.mark.parametrize("stroke, needle", [([0, 1], "1 <= start <= end <= 1"), ([1, 3], "<= 1"),
                                            ([2, 1], "1 <= start <= end")])
def test_a_stroke_out_of_range_names_the_file_and_the_rule(tmp_path, stroke, needle):
    folder = make_library_dir(tmp_path / "library")
    raised = list(REST)
    raised[7] -= 0.5
    write_motion(folder, "bad_stroke", "pointing", [REST, raised, REST], stroke=stroke)
    with pytest.raises(LibraryError, match="bad_stroke") as caught:
        load_library(folder)
    assert "stroke" in str(caught.value) and needle in str(caught.value)


def test_a_motion_without_a_stroke_gets_the_largest_excursion_with_a_warning(tmp_path, caplog):
    folder = make_library_dir(tmp_path / "library")
    small, large = list(REST), list(REST)
    small[7] -= 0.3
    large[7] -= 0.9
    write_motion(folder, "no_stroke", "pointing", [REST, small, large, small, REST])
    library = load_library(folder)
    assert library.get("no_stroke").stroke is None and library.get("no_stroke").stroke_span == (2, 2)
    assert "no_stroke.yaml: no `stroke" in caplog.text
    assert library.get("neutral_rest").stroke_span == (0, 0)  # a pose is its own stroke


def write_fields(folder, name: str, **fields: str):
    """A motion file from raw YAML values, so that a test can write any type."""
    lines = {"name": name, "class": "pointing", "description": "typed test motion",
             "keyframes": str([REST, [v - 0.1 for v in REST], REST]), **fields}
    path = folder / f"{name}.yaml"
    path.write_text("".join(f"{key}: {value}\n" for key, value in lines.items()))
    return path


@pytest.mark.parametrize("fields,named", [
    ({"duration": '"2"'}, "duration: Input should be a valid number, got str '2'"),
    ({"duration": "true"}, "duration: Input should be a valid number, got bool True"),
    ({"stroke": "[1.0, 1]"}, "stroke.0: Input should be a valid integer, got float 1.0"),
    ({"stroke": '["1", "1"]'}, "stroke.0: Input should be a valid integer, got str '1'"),
    ({"description": "2024-01-01"}, "description: Input should be a valid string, got date"),
    ({"keyframes": str([REST, ["0.1"] * 14, REST])}, "keyframes.1.0: Input should be a valid number, got"),
])
def test_a_value_of_the_wrong_type_is_refused_not_coerced(tmp_path, fields, named):
    folder = make_library_dir(tmp_path / "lib")
    path = write_fields(folder, "typed_one", **fields)
    with pytest.raises(LibraryError) as refused:
        load_library(folder)
    message = str(refused.value)
    assert message.startswith(f"{path}: motion 'typed_one': ") and named in message, message
    assert "\n" not in message and len(message) < 600  # one line, the first problems only


def test_whole_numbers_are_numbers(tmp_path):
    folder = make_library_dir(tmp_path / "lib")
    write_fields(folder, "whole_numbers", duration="2", stroke="[1, 1]",
                 keyframes=str([[0] * 14, [0.1] * 14, [0] * 14]))
    entry = load_library(folder).get("whole_numbers")
    assert entry.duration == 2.0 and entry.stroke == (1, 1) and entry.keyframes[0] == (0.0,) * 14
