"""The cost ledger (benchmarks/ledger.py): its committed reference names every workload once, and its table
marks a workload more than 10 % dearer than the reference.  Nothing here is timed."""

from __future__ import annotations

from benchmarks import ledger


def test_the_reference_costs_every_workload_of_the_ledger():
    reference = ledger.read_reference()
    names = [name for name, _, _ in ledger.WORKLOADS]
    assert len(set(names)) == len(names)
    assert list(reference["workloads"]) == names
    assert reference["kernel_ns_per_point_step"] > 0
    for w in reference["workloads"].values():
        assert w["cost_M_point_steps"] == round(w["cpu_s"] * 1e3 / reference["kernel_ns_per_point_step"], 1)


def test_a_workload_more_than_ten_percent_dearer_is_named():
    reference = {
        "kernel_ns_per_point_step": 10.0,
        "workloads": {"a": {"cost_M_point_steps": 100.0}, "b": {"cost_M_point_steps": 100.0}},
    }
    now = {
        "kernel_ns_per_point_step": 5.0,
        "workloads": {
            "a": {"cpu_s": 0.5, "cost_M_point_steps": 111.0},
            "b": {"cpu_s": 0.5, "cost_M_point_steps": 109.0},
        },
    }
    table = ledger.markdown(now, reference)
    assert "| a | 0.50 | 111 | 100.0 | 1.11 **dearer** |" in table
    assert "| b | 0.50 | 109 | 100.0 | 1.09 |" in table
    assert table.rstrip().endswith("more than 1.10x dearer: a")
