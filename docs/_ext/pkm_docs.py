# SPDX-License-Identifier: BSD-2-Clause
"""Sphinx extension of the documentation site: pages take what this build
generated instead of retyped copies.

A page line

    % pkm-generated PKM4PUU.md

is replaced, before the page is parsed, by the Markdown file of that name in
the build's generated folder (config value pkm_generated_dir, from
PKM_DOCS_GENERATED): the FMU reference that <id>_files --markdown writes
from the variable tables, and the figure tables that docs/build_docs.py
writes from this build's runs. (A line starting with % is a MyST comment, so
the marker shows nothing by itself.) A missing file is a warning (an error
under -W, as the site is built) and a visible gap, never an older run's
numbers.
"""
import re
from pathlib import Path

from sphinx.errors import ExtensionError
from sphinx.util import logging

logger = logging.getLogger(__name__)

MARKER = re.compile(r"^% pkm-generated (\S+)[ \t]*$", re.M)


def _substitute(app, docname, source):
    def replace(m):
        base = app.config.pkm_generated_dir
        if not base:
            raise ExtensionError(f"{docname}: pkm-generated {m.group(1)}: no generated folder "
                                 "(build the site with docs/build_docs.py)")
        path = Path(base) / m.group(1)
        if not path.is_file():
            # a warning (an error under -W) and a visible gap, never an older run's numbers
            logger.warning(f"pkm-generated: {path} does not exist (its generator did not run)",
                           location=docname, type="pkm", subtype="generated")
            return f"```{{warning}}\nNot generated in this build: {m.group(1)}.\n```\n"
        app.env.note_dependency(str(path))
        return path.read_text(encoding="utf-8")

    source[0] = MARKER.sub(replace, source[0])


def setup(app):
    app.add_config_value("pkm_generated_dir", "", "env")
    app.connect("source-read", _substitute)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
