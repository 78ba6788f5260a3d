"""Imports the abuopt module: installed, on PYTHONPATH, or else from this checkout's build/python."""
import os
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def import_abuopt():
    try:
        import abuopt
        return abuopt
    except ImportError:
        pass
    build = os.path.join(REPO, "build", "python")
    sys.path.insert(0, build)
    try:
        import abuopt
        return abuopt
    except ImportError as e:
        sys.exit(f"cannot import abuopt ({e}): build it (cmake --build build) or set PYTHONPATH=<build>/python "
                 f"(docs/python.md)")
