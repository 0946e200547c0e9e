# SPDX-License-Identifier: BSD-2-Clause
"""The example programs under examples/, loaded as modules by file path so
that their tests can call their functions (they are scripts, not a package)."""
import importlib.util
import sys

from conftest import REPO


def load_example(name):
    """examples/<name>.py as the module `name` (once per session)."""
    if name in sys.modules:
        return sys.modules[name]
    path = REPO / "examples" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses and pickling look the module up by name
    spec.loader.exec_module(module)
    return module
