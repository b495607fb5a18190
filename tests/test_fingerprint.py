"""The fingerprint (benchmarks/fingerprint.py): a small fixed study through every stage, compared with the
reference committed from another run, stage by stage.  A machine on which this fails computes other bits
than the reference machine did: the message names the first stage that differs, and
``python -m benchmarks.bench fingerprint`` prints the whole fingerprint and the machine to compare."""

from __future__ import annotations

import pytest

from benchmarks import fingerprint


@pytest.fixture(scope="module")
def stages():
    return fingerprint.study()


def test_the_study_covers_every_kind_of_verdict(stages):
    """The study means something only if its lines reach what they are meant to: a torus, a certified long
    cycle and chaos (the chaotic line's three labels), and a continuation with typed events."""
    assert stages["torus_digits"] != "none" and stages["order_gaps"] != "none"
    assert stages["candidate_periods"] != "none" and stages["continuation"] != "none"
    assert [s.split("/")[0] for s in stages["chaos_statistics"].split()] == ["-4", "-4", "-4"]


def test_the_fingerprint_is_the_reference_one(stages):
    reference = fingerprint.read_reference()
    assert set(reference) == set(fingerprint.STAGES)
    differs = fingerprint.first_difference(stages, reference)
    assert differs is None, (
        f"first stage that differs from benchmarks/fingerprint.txt: {differs} "
        f"({stages[differs]} here, {reference[differs]} there); machine: {fingerprint.machine()}"
    )


def test_a_difference_is_named_by_its_first_stage(stages):
    changed = dict(stages, order_gaps="0" * 16, response="0" * 16)
    assert fingerprint.first_difference(changed, stages) == "order_gaps"
    chaos = stages["chaos_statistics"].split()
    label, exponent, spread = chaos[0].split("/")
    near = " ".join([f"{label}/{float(exponent) * 1.1:.1e}/{spread}", *chaos[1:]])
    far = " ".join([f"{label}/{float(exponent) * 2:.1e}/{spread}", *chaos[1:]])
    assert fingerprint.first_difference(dict(stages, chaos_statistics=near), stages) is None
    assert fingerprint.first_difference(dict(stages, chaos_statistics=far), stages) == "chaos_statistics"


def test_the_designs_hashed_are_the_shipped_ones_whatever_lies_beside_them():
    """The coefficients stage hashes the designs the shipped config names, by name: a user's own design file
    written into ``config/designs/`` (``geardyn new-design``) changes no stage."""
    import yaml  # noqa: PLC0415

    config = yaml.safe_load((fingerprint.ROOT / "config" / "config.yaml").read_text())
    assert set(fingerprint.SHIPPED_DESIGNS) == set(config["designs"])
