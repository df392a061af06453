"""The project root and tools/render_docs.py (not a package) as a module, for the tests of the pages' numbers."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _renderer():
    spec = importlib.util.spec_from_file_location("render_docs", ROOT / "tools" / "render_docs.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


#: tools/render_docs.py, loaded once.
rd = _renderer()
