"""Root conftest: pytest's doctest collection imports every module of the package; pumpup.mitsuba needs the
optional Mitsuba 3 (the render extra), so it is skipped where mitsuba is not installed."""

import importlib.util


def _have(name):
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


collect_ignore = [] if _have("mitsuba") else ["pumpup/mitsuba.py"]
