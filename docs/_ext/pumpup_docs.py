"""Sphinx directives that generate pumpup's reference pages from the code, so they cannot drift from it.

``.. pumpup-cli::``
    the command-line reference: every subcommand (and nested subcommand) of :func:`pumpup.cli.build_parser`, with its
    usage, description and every option, walked from the argparse parser itself.
``.. pumpup-routes::``
    the albedo engine's routing table, :func:`pumpup.engine.routes.describe`.
``.. pumpup-models::``
    the registered model types and their parameters (what ``pumpup models`` prints).
``.. pumpup-table:: NAME``
    a Markdown table generated from a file the repository generates (``pumpup_numbers.TABLES``).
``:pumpup-value:`KEY```
    a number computed when the site is built (``pumpup_numbers.VALUES``); in Markdown ``{pumpup-value}`KEY```.

:func:`cli_reference_rst` is the text the first directive parses; ``tests/project/test_docs.py`` checks that every
subcommand of the parser appears in it.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import re

#: underline characters of the section levels the CLI reference uses, below the page's own title
_LEVELS = "=-~^"


def _subparsers(parser: argparse.ArgumentParser):
    """(name, parser) of each subcommand of ``parser``, in the order they were added."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help for a in action._choices_actions}
            for name, sub in action.choices.items():
                yield name, sub, helps.get(name) or ""


def walk(parser: argparse.ArgumentParser, path=()):
    """(path of subcommand names, parser, one-line help) of every subcommand at every depth, depth first."""
    for name, sub, help_ in _subparsers(parser):
        yield (*path, name), sub, help_
        yield from walk(sub, (*path, name))


def _indent(text: str) -> list[str]:
    return ["   " + line if line.strip() else "" for line in text.splitlines()]


def _help_text(parser: argparse.ArgumentParser) -> str:
    """``parser``'s ``--help`` at a fixed width (the page's column), so the pages do not depend on the terminal."""
    formatter_class = parser.formatter_class

    def fixed(prog, _cls=formatter_class):
        try:
            return _cls(prog, width=72)
        except TypeError:
            return _cls(prog)

    parser.formatter_class = fixed
    try:
        return parser.format_help()
    finally:
        parser.formatter_class = formatter_class


def cli_reference_rst(parser: argparse.ArgumentParser | None = None) -> str:
    """ReStructuredText of the command-line reference: one section per subcommand, its ``--help`` verbatim."""
    if parser is None:
        from pumpup.cli import build_parser

        parser = build_parser()
    lines = [".. _cli-pumpup:", "", "``pumpup``", _LEVELS[0] * 10, "", ".. code-block:: text", "",
             *_indent(_help_text(parser)), ""]
    for path, sub, help_ in walk(parser):
        title = "``pumpup " + " ".join(path) + "``"
        anchor = "cli-" + "-".join(path)
        lines += [f".. _{anchor}:", "", title, _LEVELS[min(len(path), len(_LEVELS) - 1)] * len(title), ""]
        if help_:
            lines += [help_.replace("*", r"\*").replace("`", "'") + ".", ""]
        lines += [".. code-block:: text", "", *_indent(_help_text(sub)), ""]
    return "\n".join(lines)


def routing_table_rst() -> str:
    """ReStructuredText of the albedo engine's routing table, :func:`pumpup.engine.routes.describe`, verbatim."""
    from pumpup.engine.routes import describe

    return "\n".join([".. code-block:: text", "", *_indent(describe()), ""])


def model_list_rst() -> str:
    """ReStructuredText of the registered models and their parameters, as ``pumpup models`` prints them."""
    from pumpup.cli import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        main(["models"])
    return "\n".join([".. code-block:: text", "", *_indent(out.getvalue()), ""])


def _directive(text, titles: bool):
    """A directive class that parses ``text()`` (reStructuredText) in place; ``titles``: it holds sections.  Sphinx
    is imported here, so the functions above work without it (the fast tests use them).
    """
    from docutils import nodes
    from docutils.statemachine import StringList
    from sphinx.util.docutils import SphinxDirective
    from sphinx.util.nodes import nested_parse_with_titles

    class Generated(SphinxDirective):
        has_content = False

        def run(self):
            self.env.note_dependency(__file__)
            node = nodes.section() if titles else nodes.container()
            content = StringList(text().splitlines(), source=text.__name__)
            if titles:
                nested_parse_with_titles(self.state, content, node)
            else:
                self.state.nested_parse(content, self.content_offset, node)
            return node.children

    return Generated


def _table_directive():
    """``pumpup-table NAME``: the Markdown of ``pumpup_numbers.TABLES[NAME]()``, parsed in place."""
    import pumpup_numbers
    from docutils.statemachine import StringList
    from sphinx.util.docutils import SphinxDirective

    class Table(SphinxDirective):
        required_arguments = 1
        has_content = False

        def run(self):
            from docutils import nodes

            name = self.arguments[0]
            if name not in pumpup_numbers.TABLES:
                raise self.error(f"pumpup-table: unknown table {name!r}; known: {', '.join(pumpup_numbers.TABLES)}")
            self.env.note_dependency(pumpup_numbers.__file__)
            node = nodes.container()
            text = pumpup_numbers.TABLES[name]()
            self.state.nested_parse(StringList(text.splitlines(), source=f"pumpup-table {name}"), self.content_offset,
                                    node)
            return node.children

    return Table


def value_role(name, rawtext, text, lineno, inliner, options=None, content=None):
    """``:pumpup-value:`KEY```: the number ``pumpup_numbers.VALUES[KEY]`` computes, as text."""
    import pumpup_numbers
    from docutils import nodes

    key = text.strip()
    if key not in pumpup_numbers.VALUES:
        msg = inliner.reporter.error(f"pumpup-value: unknown key {key!r}", line=lineno)
        return [inliner.problematic(rawtext, rawtext, msg)], [msg]
    return [nodes.Text(_value_text(key))], []


_VALUE_CACHE: dict = {}


def _value_text(key: str) -> str:
    import pumpup_numbers

    if key not in _VALUE_CACHE:
        _VALUE_CACHE[key] = pumpup_numbers.VALUES[key].text()
    return _VALUE_CACHE[key]


#: modules with public names (an ``__all__``) that get no reference page, with the reason
EXCLUDED = {
    "pumpup.warmup": "a command (pumpup warmup), documented in the CLI reference",
    "pumpup.figures": "the pumping figures' data, shown by the gallery",
    "pumpup.plots": "the figures of figures/, shown by the gallery",
    "pumpup.published": "the papers' printed values, shown by pumpup reproduce",
    "pumpup.costs": "the cost tables of pumpup reproduce --only costs",
}


def documented_modules() -> list[str]:
    """The modules of the reference (``reference/modules/``): every package of pumpup and every module with an
    ``__all__``, but private ones and :data:`EXCLUDED`, sorted by name.
    """
    import importlib
    import pkgutil

    import pumpup

    out = []
    for info in pkgutil.walk_packages(pumpup.__path__, "pumpup."):
        if any(part.startswith("_") for part in info.name.split(".")) or info.name in EXCLUDED:
            continue
        module = importlib.import_module(info.name)
        if info.ispkg or getattr(module, "__all__", None):
            out.append(info.name)
    return sorted(out)


def public_names(module_name: str) -> list[str]:
    """The public names of a module: its ``__all__``, sorted."""
    import importlib

    module = importlib.import_module(module_name)
    return sorted(getattr(module, "__all__", ()))


def _kind(module_name: str, name: str) -> str:
    """The autodoc directive for ``module_name.name``: class, exception, function or data."""
    import importlib
    import inspect

    obj = getattr(importlib.import_module(module_name), name)
    if inspect.isclass(obj):
        return "exception" if issubclass(obj, BaseException) else "class"
    if callable(obj) and not inspect.ismodule(obj):
        return "function"
    return "data"


def module_page_rst(module_name: str) -> str:
    """ReStructuredText of one module's reference page: its docstring and an autosummary of its ``__all__``."""
    import pumpup

    lines = [module_name, "=" * len(module_name), "", f".. automodule:: {module_name}", "   :no-members:"]
    if module_name.removeprefix("pumpup.") in pumpup.__all__:  # pumpup.divergence: a function of the same name
        lines.append("   :no-index:")
    lines.append("")
    names = public_names(module_name)
    if names:
        lines += [f".. currentmodule:: {module_name}", "", ".. rubric:: Public names", "", ".. autosummary::",
                  "   :nosignatures:", "", *(f"   {n}" for n in names), ""]
        for n in names:
            lines += [f".. auto{_kind(module_name, n)}:: {n}", ""]
    return "\n".join(lines)


def write_module_pages(app) -> None:
    """Write ``reference/modules/<module>.rst`` for every module of :func:`documented_modules` (only where the text
    changes, so an unchanged page is not rebuilt).
    """
    import os

    outdir = os.path.join(app.srcdir, "reference", "modules")
    os.makedirs(outdir, exist_ok=True)
    for name in documented_modules():
        path = os.path.join(outdir, f"{name}.rst")
        text = module_page_rst(name)
        if not os.path.exists(path) or open(path).read() != text:
            with open(path, "w") as fh:
                fh.write(text)


_LITERAL = re.compile(r"(``.*?``|`[^`]*`_?|:[a-z:]+:`[^`]*`)")
_TRAILING_UNDERSCORE = re.compile(r"(?<=\w)_(?=[\s,.;:)\]|+-]|$)")


def plain_text_math(line: str) -> str:
    """``line`` with the plain-text mathematics of pumpup's docstrings kept literal: ``|x|`` is an absolute value, not a
    substitution, and ``r_`` a subscript, not a link.  Literals and roles are left alone, and so are table rows.
    """
    stripped = line.lstrip()
    if stripped.startswith(("+-", "+=")) or (stripped.startswith("|") and stripped.rstrip().endswith("|")):
        return line
    parts = _LITERAL.split(line)
    for i in range(0, len(parts), 2):
        parts[i] = _TRAILING_UNDERSCORE.sub(r"\\_", parts[i].replace("|", r"\|"))
    return "".join(parts)


def escape_docstring(app, what, name, obj, options, lines) -> None:
    """``autodoc-process-docstring``: :func:`plain_text_math` on every line outside literal blocks."""
    in_literal = False
    literal_indent = 0
    for i, line in enumerate(lines):
        indent = len(line) - len(line.lstrip())
        if in_literal:
            if line.strip() and indent <= literal_indent:
                in_literal = False
            else:
                continue
        lines[i] = plain_text_math(line)
        if line.rstrip().endswith("::") or line.lstrip().startswith(">>>"):
            in_literal = line.rstrip().endswith("::")
            literal_indent = indent


def setup(app):
    """Register the directives and the hooks with Sphinx."""
    app.connect("builder-inited", write_module_pages, priority=100)
    app.connect("autodoc-process-docstring", escape_docstring)
    app.add_directive("pumpup-cli", _directive(cli_reference_rst, titles=True))
    app.add_directive("pumpup-routes", _directive(routing_table_rst, titles=False))
    app.add_directive("pumpup-models", _directive(model_list_rst, titles=False))
    app.add_directive("pumpup-table", _table_directive())
    app.add_role("pumpup-value", value_role)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
