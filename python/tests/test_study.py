"""The Python module against the command line: the same study gives the same results.json,
and a bad case raises with its field named."""

import json
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

import counterpoise

ROOT = pathlib.Path(__file__).resolve().parents[2]
TWO_LINK = ROOT / "cases" / "two_link.json"


def cli() -> str:
    """The command line built beside the module (release, then debug), or on PATH."""
    for profile in ("release", "debug"):
        exe = ROOT / "target" / profile / "counterpoise"
        if exe.exists():
            return str(exe)
    exe = shutil.which("counterpoise")
    if exe is None:
        pytest.skip("no counterpoise binary: cargo build --release first")
    return exe


def without_run_details(doc: dict) -> dict:
    """results.json without what differs between any two runs (timings, date, threads)."""
    doc = json.loads(json.dumps(doc))
    for key in ("timings", "date", "jobs"):
        doc["metadata"].pop(key, None)
    return doc


def test_a_study_from_python_equals_the_command_line(tmp_path):
    out = tmp_path / "out"
    subprocess.run(
        [cli(), "run", str(TWO_LINK), "--out", str(out), "--quiet"],
        check=True,
        capture_output=True,
    )
    from_cli = json.loads((out / "results.json").read_text())
    results = counterpoise.load_case(TWO_LINK).run_study()
    assert without_run_details(results.document) == without_run_details(from_cli)
    # The typed view agrees with the document it reads.
    ranked = results.ranked
    assert [v.rank for v in ranked] == list(range(1, len(ranked) + 1))
    assert all(v.status == "feasible" and v.verification_residual < 1e-9 for v in ranked)
    chart = results.torque_charts[0]
    assert isinstance(chart.t, np.ndarray) and chart.t.ndim == 1
    assert all(c.shape == chart.t.shape for c in chart.curves.values())
    assert next(iter(chart.curves)) == "UB"


def test_a_case_from_a_dict_is_the_case_from_its_file():
    document = json.loads(TWO_LINK.read_text())
    from_dict = counterpoise.load_case(document)
    from_file = counterpoise.load_case(TWO_LINK)
    assert from_dict.to_dict() == from_file.to_dict() == document
    assert (from_dict.name, from_dict.bodies, from_dict.dmax) == (
        from_file.name,
        from_file.bodies,
        from_file.dmax,
    )
    assert repr(from_file).startswith("<Case 'two_link'")


def test_variants_match_the_command_line():
    listed = subprocess.run(
        [cli(), "variants", str(TWO_LINK), "--json"], check=True, capture_output=True, text=True
    ).stdout
    expected = [(v["elements"], v["status"]) for v in json.loads(listed)["variants"]]
    got = counterpoise.load_case(TWO_LINK).variants()
    assert [([e for e in v.document["elements"]], v.status) for v in got] == expected
    assert {v.status for v in got} <= {"balanced", "degenerate", "unrealizable", "infeasible"}


def test_a_bad_case_raises_with_the_field_named():
    document = json.loads(TWO_LINK.read_text())
    document["bodies"][0]["mass"] = -1.0
    with pytest.raises(counterpoise.CounterpoiseError) as raised:
        counterpoise.load_case(document)
    assert "bodies[0].mass" in str(raised.value)
    assert isinstance(raised.value, ValueError)


def test_an_unknown_dmax_is_refused_with_the_option_named():
    case = counterpoise.load_case(TWO_LINK)
    with pytest.raises(counterpoise.CounterpoiseError, match="--dmax must be at least 1"):
        case.run_study(dmax=0)


def test_a_urdf_robot_imports_as_the_command_line_writes_it():
    urdf = ROOT / "cases" / "arm6.urdf"
    written = subprocess.run(
        [cli(), "import-urdf", str(urdf)], check=True, capture_output=True, text=True
    ).stdout
    case = counterpoise.import_urdf(urdf)
    assert case.to_dict() == json.loads(written)
    assert len(case.actuators) == 6
