"""The command line of the scripts that store a generated JSON file in tables/ for the documentation to read:
compute it and write it atomically, or, with ``--read``, read the stored one.

    python scripts/make/<script>.py [--out DIR] [--read]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout

from pumpup.tables import atomic_path  # noqa: E402

TABLES = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "tables")


def computed_or_stored(filename: str, run: Callable[[], dict], description: str,
                       sort_keys: bool = False) -> tuple[dict, str | None]:
    """Parse ``--out DIR`` (default tables/) and ``--read``; return the data (``run()``'s, written atomically to
    DIR/``filename``, or the stored file's with ``--read``) and the path written (None when read).
    """
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--out", default=TABLES)
    ap.add_argument("--read", action="store_true", help="print the table of the stored file instead of computing")
    a = ap.parse_args()
    path = os.path.join(a.out, filename)
    if a.read:
        with open(path) as fh:
            return json.load(fh), None
    data = run()
    write(path, data, sort_keys)
    return data, path


def write(path: str, data: dict, sort_keys: bool = False) -> None:
    """Write ``data`` to ``path`` as indented JSON, atomically (the file is whole or absent)."""
    with atomic_path(path) as tmp, open(tmp, "w") as fh:
        json.dump(data, fh, indent=1, sort_keys=sort_keys)


def main(filename: str, run: Callable[[], dict], markdown: Callable[[dict], str], description: str,
         sort_keys: bool = False) -> int:
    """The whole command line of a script whose output is its page's table: :func:`computed_or_stored`, then print
    ``markdown(data)`` and the path written; return the exit status.
    """
    data, wrote = computed_or_stored(filename, run, description, sort_keys=sort_keys)
    print(markdown(data))
    if wrote:
        print("wrote", wrote)
    return 0
