"""fdmsubgrid.files: result and record files are written whole or not at all (docs/cases.md)."""
import json
import time

import pytest

from fdmsubgrid import files


def test_write_results_stamps_wall_time_and_date_and_round_trips(tmp_path):
    out = tmp_path / "deeper" / "results.json"          # the folder is made
    started = time.time() - 2.5
    results = files.write_results(str(out), dict(case="demo", rows=[dict(eps=0.1, U=0.7389)]), started)
    assert 2.5 <= results["wall_seconds"] < 60
    assert results["date"] == time.strftime("%Y-%m-%d")
    assert json.loads(out.read_text()) == results
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
