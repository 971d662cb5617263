"""Recording files (record.py-compatible CSV) and `urdsl plot`."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.cli import main
from urdsl.robot.csvfile import (
    CsvWriter,
    RecordingFormatError,
    expand_names,
    read_recording,
)
from urdsl.robot.plot import plot_recording

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _write(path, rows=50):
    names = ["timestamp", "actual_q", "actual_TCP_pose", "robot_mode", "runtime_state"]
    types = ["DOUBLE", "VECTOR6D", "VECTOR6D", "INT32", "UINT32"]
    with CsvWriter(path, names, types) as writer:
        for i in range(rows):
            t = 0.002 * i
            q = [math.sin(t + j) for j in range(6)]
            pose = [0.1 * j + t for j in range(6)]
            writer.write([1000.0 + t, q, pose, 7, 2])
    return names


def test_header_expands_vectors_as_record_py_does():
    assert expand_names(["timestamp", "actual_q", "elbow_position", "safety_mode"],
                        ["DOUBLE", "VECTOR6D", "VECTOR3D", "INT32"]) == [
        "timestamp", *[f"actual_q_{i}" for i in range(6)],
        "elbow_position_0", "elbow_position_1", "elbow_position_2", "safety_mode"]


def test_written_file_is_space_separated_with_one_header(tmp_path):
    path = tmp_path / "run.csv"
    _write(path, rows=3)
    lines = path.read_text().splitlines()
    assert lines[0].split(" ")[:3] == ["timestamp", "actual_q_0", "actual_q_1"]
    assert len(lines[0].split(" ")) == 1 + 6 + 6 + 2
    assert len(lines) == 4
    assert all(len(line.split(" ")) == 15 for line in lines)
    assert lines[1].split(" ")[0] == "1000.0"
    assert lines[1].split(" ")[-2:] == ["7", "2"]


def test_booleans_are_numbers_so_every_column_reads_as_float(tmp_path):
    path = tmp_path / "b.csv"
    with CsvWriter(path, ["timestamp", "flag"], ["DOUBLE", "BOOL"]) as writer:
        writer.write([0.5, True])
        writer.write([1.0, False])
    recording = read_recording(path)
    assert list(recording.field("flag")) == [1.0, 0.0]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64),
                         min_size=7, max_size=7), min_size=1, max_size=20))
def test_values_read_back_exactly(tmp_path_factory, rows):
    path = tmp_path_factory.mktemp("csv") / "r.csv"
    with CsvWriter(path, ["timestamp", "actual_q"], ["DOUBLE", "VECTOR6D"]) as writer:
        for row in rows:
            writer.write([row[0], row[1:]])
    recording = read_recording(path)
    assert recording.rows == len(rows)
    np.testing.assert_array_equal(recording.field("timestamp"), [r[0] for r in rows])
    np.testing.assert_array_equal(recording.field("actual_q"), [r[1:] for r in rows])


def test_reader_names_the_bad_line(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("timestamp a\n0.0 1\n\n0.1 x\n")
    with pytest.raises(RecordingFormatError, match=r"bad.csv:4: 'x' is not a number"):
        read_recording(path)
    path.write_text("timestamp a\n0.0 1 2\n")
    with pytest.raises(RecordingFormatError, match=r"bad.csv:2: 3 values, but the header "
                                                   r"names 2 columns"):
        read_recording(path)
    path.write_text("")
    with pytest.raises(RecordingFormatError, match="empty"):
        read_recording(path)


def test_reader_takes_comma_separated_files_too(tmp_path):
    path = tmp_path / "c.csv"
    path.write_text("timestamp,actual_q_0,actual_q_1\n0,1,2\n1,3,4\n")
    recording = read_recording(path)
    assert recording.fields() == ["timestamp", "actual_q"]
    np.testing.assert_array_equal(recording.field("actual_q"), [[1, 2], [3, 4]])


def test_plot_writes_a_png(tmp_path):
    csv = tmp_path / "run.csv"
    _write(csv)
    png = tmp_path / "run.png"
    summary = plot_recording(csv, png, ["actual_q", "actual_TCP_pose", "robot_mode"])
    assert png.read_bytes()[:8] == PNG_MAGIC
    assert summary.samples == 50
    assert summary.fields == ("actual_q", "actual_TCP_pose", "robot_mode")
    assert summary.duration == pytest.approx(0.098)


def test_plot_command_default_fields_and_errors(tmp_path, capsys):
    csv = tmp_path / "run.csv"
    _write(csv)
    png = tmp_path / "out.png"
    assert main(["plot", str(csv), "-o", str(png)]) == 0
    assert png.read_bytes()[:8] == PNG_MAGIC
    assert "actual_q; 50 samples" in capsys.readouterr().err
    assert main(["plot", str(csv), "--fields", "actual_qd", "-o", str(png)]) == 1
    err = capsys.readouterr().err
    assert "no field 'actual_qd'" in err and "actual_TCP_pose" in err
    assert main(["plot", str(tmp_path / "missing.csv"), "-o", str(png)]) == 1
    assert "no such file" in capsys.readouterr().err


def test_plot_single_column_like_example_plotting(tmp_path):
    csv = tmp_path / "robot_data.csv"
    csv.write_text("timestamp target_q_0 target_q_1\n" +
                   "".join(f"{0.008 * i} 0 {0.01 * i}\n" for i in range(100)))
    png = tmp_path / "q1.png"
    assert main(["plot", str(csv), "--fields", "target_q_1", "-o", str(png)]) == 0
    assert png.read_bytes()[:8] == PNG_MAGIC
