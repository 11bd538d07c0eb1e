"""fdmsubgrid.files: result and record files are written whole or not at all (docs/cases.md)."""
import json
import time

import pytest

from fdmsubgrid import files


def test_write_results_stamps_wall_time_and_date_and_round_trips(tmp_path):
    """A case's results file (fdmsubgrid.results, written through files.write_json): stamped with the
    wall time and the date, whole, its folder made."""
    import os
    from conftest import PROJECT
    from fdmsubgrid import results as results_file
    out = tmp_path / "deeper" / "results.json"          # the folder is made
    started = time.time() - 2.5
    script = os.path.join(PROJECT, "cases", "wallSqueeze", "wallSqueeze.py")
    data = results_file.write_results(str(out), script, [], {}, [], dict(case="demo", eps=[0.1], U=[0.7389]), started)
    assert 2.5 <= data["wall_seconds"] < 60
    assert data["date"] == time.strftime("%Y-%m-%d")
    assert results_file.read_data(str(out)) == data
    assert not (tmp_path / "deeper" / "results.json.tmp").exists()


def test_a_failed_write_leaves_the_previous_file_whole(tmp_path):
    out = tmp_path / "results.json"
    files.write_json(str(out), dict(rows=[1, 2, 3]))
    before = out.read_text()
    with pytest.raises(TypeError):
        files.write_json(str(out), dict(rows=[object()]))   # not serialisable: fails before the file is touched
    assert out.read_text() == before
    files.write_atomically(str(out), b"\x00bytes")
    assert out.read_bytes() == b"\x00bytes"
