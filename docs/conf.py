"""Sphinx configuration: the user guide (the Markdown pages beside this file, through
myst-parser) and the API reference, generated from the docstrings (numpydoc).

    python -m sphinx -W --keep-going -b html docs <output directory>

The build imports the installed package (autodoc) but runs none of its computations: the
examples in docstrings and pages are shown, not executed. The command-line page prints the
argument parsers' help (``epc-fast-help`` below), which builds the parsers and nothing else.
"""

from __future__ import annotations

import argparse
import os
from contextlib import contextmanager

from docutils import nodes
from sphinx.util.docutils import SphinxDirective

import epc_fast

project = "epc_fast"
author = "the epc_fast developers"
copyright = "the epc_fast developers"
release = epc_fast.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build"]

# Markdown: links between pages as the repository has them (``[the model](model.md)``), and
# anchors for headings so that ``page.md#a-heading`` resolves.
myst_heading_anchors = 3

# The docstrings are numpydoc's sections with prose around them: no member tables (each class
# documents its own members through autodoc), no cross-reference of every type word.
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the signatures carry the annotations; numpydoc gives the types
autodoc_default_options = {"members": True, "show-inheritance": False}

html_theme = "alabaster"
html_title = f"epc_fast {release}"
html_static_path: list[str] = []


@contextmanager
def _columns(width: int):
    """argparse wraps help at $COLUMNS: a fixed width, so that the page is the same anywhere."""
    before = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = str(width)
    try:
        yield
    finally:
        if before is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = before


class CommandHelp(SphinxDirective):
    """``epc-fast-help [COMMAND]``: the ``--help`` text of ``epc-fast`` or of one of its
    sub-commands, as a literal block, from the same parser the command line uses. Without a
    command: the main help, then every sub-command's under a rubric of its own."""

    optional_arguments = 1

    def run(self):
        from epc_fast.__main__ import build_parser
        from epc_fast.commands import discover

        parser = build_parser(discover())
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        if self.arguments:
            (name,) = self.arguments
            if name not in sub.choices:
                raise self.error(f"epc-fast has no sub-command {name!r}")
            return [_help_block(sub.choices[name])]
        result = [_help_block(parser)]
        for name, command in sub.choices.items():
            result += [nodes.rubric(text=f"epc-fast {name}"), _help_block(command)]
        return result


def _help_block(parser: argparse.ArgumentParser) -> nodes.literal_block:
    with _columns(92):
        text = parser.format_help()
    block = nodes.literal_block(text, text)
    block["language"] = "text"
    return block


def setup(app):
    app.add_directive("epc-fast-help", CommandHelp)
    return {"parallel_read_safe": True}
