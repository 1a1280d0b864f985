"""pumpup's namespace: the modules of functions that share their name stay reachable as modules (issue 13, item 16)."""


def test_modules_are_not_hidden_by_their_functions():
    """Issue 13 item 16: the modules of pump, sweep and fit have names of their own."""
    import importlib
    import types

    import pumpup

    for mod, func in (("operators.pumping", "pump"), ("sweeps", "sweep"), ("fitting", "fit")):
        m = importlib.import_module(f"pumpup.{mod}")
        reached = pumpup
        for part in mod.split("."):  # pumpup.operators.pumping: attributes all the way
            reached = getattr(reached, part)
        assert isinstance(m, types.ModuleType) and reached is m
        assert callable(getattr(pumpup, func)) and getattr(m, func) is getattr(pumpup, func)
