"""A claim made from its two sides: which reasons reach its detail."""

from vic_drake.analysis.claims.claim import FAIL, NOT_EVALUATED, PASS, two_sided


def test_a_side_without_a_verdict_gives_its_reason_and_an_evaluated_one_does_not():
    c = two_sided(
        "C4",
        "paper",
        ({"ratio": 0.9}, True),
        (None, None),
        "pass: ratio <= 1.2",
        reason_sim="never shown: this side has a verdict",
        reason_real="no real log",
    )
    assert c.id == "C4" and c.statement.startswith("VS-CF")
    assert c.sim == {"ratio": 0.9} and c.real is None
    assert c.detail == "pass: ratio <= 1.2; real not evaluated: no real log"
    assert c.status == PASS
    # A value without a verdict (half of the claim not evaluated) is shown,
    # with the reason.
    c = two_sided("C6", "p", ({"n_on_ribs": 3}, None), (None, None), "d", "few ribs")
    assert c.sim == {"n_on_ribs": 3}
    assert c.detail == "d; sim not evaluated: few ribs" and c.status == NOT_EVALUATED
    c = two_sided("C5", "p", ({"x": 1.0}, True), ({"x": 0.5}, False), "d")
    assert c.detail == "d" and c.status == FAIL
