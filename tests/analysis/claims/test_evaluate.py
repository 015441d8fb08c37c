"""All claims together: the JSON form of claims.json."""

from vic_drake.analysis import claims as C


def test_evaluate_claims_json_shape():
    claims = C.evaluate_claims(C.ClaimInputs(reasons={"sim": "nothing ran"}))
    d = C.claims_to_json_dict(claims)
    assert list(d) == [f"C{i}" for i in range(1, 8)]
    for c in d.values():
        assert c["pass"] is False and c["sim"] is None
        assert "nothing ran" in c["detail"]
        assert c["status"] == "not evaluated"
