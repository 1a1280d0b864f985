"""pumpup.costs (000 Tables 1 and 5): the report runs and carries the published values; the
timings themselves depend on the machine and are never asserted."""

import pumpup.costs as costs


def test_cost_report_lists_every_model_with_its_published_value():
    r = costs.measure(n=4000, repeat=1)
    assert set(r) == set(costs.SPECS)
    assert all(v["eval"] > 0 and v["sample"] > 0 for v in r.values())
    text = costs.report(r)
    for name, pub in {**costs.TABLE1, **costs.TABLE5}.items():
        assert f"| {name} | {pub:g} |" in text
    assert "320" in text and "1516" in text
