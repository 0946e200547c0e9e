# SPDX-License-Identifier: BSD-2-Clause
"""The package's optional dependencies, its extras (pyproject.toml's
[project.optional-dependencies]: plots, calibration, references): which
extra installs a module, read from the installed package's metadata, and
the one-line error that says so when a module is missing.

    require("pkm4puu engines", "pinocchio", "mujoco")   # MissingExtra unless both are installed
"""
from __future__ import annotations

import importlib.metadata
import importlib.util
import re

PACKAGE = "pkm4puu"
# The distribution that installs a module, where their names differ.
DISTRIBUTIONS = {"pinocchio": "pin"}
_EXTRA_REQUIREMENT = re.compile(r"""^\s*([A-Za-z0-9][A-Za-z0-9._-]*).*;.*\bextra\s*==\s*["']([^"']+)["']""")


class MissingExtra(ModuleNotFoundError):
    """An optional module is not installed. str(): "<what> needs <modules>
    (not installed): pip install 'pkm4puu[<extra>]'", one line; `needs`:
    the same without <what>."""

    def __init__(self, what, modules):
        self.needs = f"needs {', '.join(modules)} (not installed): {install_command(modules)}"
        super().__init__(f"{what} {self.needs}", name=modules[0])


def extras() -> dict:
    """{extra: set of the distributions it installs} of the installed
    package (empty when its metadata cannot be read)."""
    try:
        requirements = importlib.metadata.requires(PACKAGE) or []
    except importlib.metadata.PackageNotFoundError:
        return {}
    out = {}
    for requirement in requirements:
        m = _EXTRA_REQUIREMENT.match(requirement)
        if m:
            out.setdefault(m.group(2), set()).add(m.group(1).lower())
    return out


def install_command(modules) -> str:
    """The pip command that installs the packages `modules` (top-level
    import names): the smallest extra of the package that holds every one
    of their distributions, else the distributions themselves."""
    wanted = {DISTRIBUTIONS.get(m, m).lower() for m in modules}
    holding = sorted((len(dists), extra) for extra, dists in extras().items() if wanted <= dists)
    if holding:
        return f"pip install '{PACKAGE}[{holding[0][1]}]'"
    return "pip install " + " ".join(sorted(wanted))


def missing(*modules) -> list:
    """The top-level packages of `modules` that are not installed."""
    out = []
    for module in modules:
        top = module.split(".")[0]
        if importlib.util.find_spec(top) is None and top not in out:
            out.append(top)
    return out


def require(what: str, *modules) -> None:
    """MissingExtra naming `what` and the extra to install, unless every
    module of `modules` is installed."""
    absent = missing(*modules)
    if absent:
        raise MissingExtra(what, absent)


def import_module(module: str, what: str):
    """importlib.import_module(module), or MissingExtra naming `what` when it
    is not installed."""
    require(what, module)
    return importlib.import_module(module)
