# SPDX-License-Identifier: BSD-2-Clause
# Sphinx configuration of the documentation site. Built by docs/build_docs.py
# (ctest docs_build), which runs Doxygen
# on pkm.h first and passes the build tree's generated files through the
# environment: PKM_DOCS_DOXYGEN_XML (Doxygen's XML of pkm.h) and
# PKM_DOCS_GENERATED (the FMU reference pages and the figures of this build's runs).
import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent / "python"))  # autodoc imports pkm4puu from the checkout

from pkm4puu import __version__  # noqa: E402  (one version: CMake's project())

project = "PKM4PUU"
author = "The PKM4PUU authors"
copyright = "2026, The PKM4PUU authors"
version = release = __version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "breathe",
    "pkm_docs",
]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "requirements.txt"]
myst_heading_anchors = 4  # README-style links to section anchors (#the-model)
suppress_warnings = ["myst.header"]  # the included CHANGELOG.md starts at level 1 below the page's title

html_theme = "furo"
html_title = f"PKM4PUU {release}"

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "undoc-members": False}

breathe_projects = {"pkm": os.environ.get("PKM_DOCS_DOXYGEN_XML", str(HERE / "_build" / "doxygen" / "xml"))}
breathe_default_project = "pkm"
breathe_domain_by_extension = {"h": "c"}

pkm_generated_dir = os.environ.get("PKM_DOCS_GENERATED", "")
