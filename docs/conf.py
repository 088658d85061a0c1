"""Sphinx configuration of the cyclecoord documentation.

Build it with ``sphinx-build -W --keep-going -b html docs docs/_build/html`` after
``pip install -e ".[docs]"``.  Why these tools:

* **Sphinx + autodoc/autosummary** because the API reference must come from the
  docstrings themselves (one source, no copy to drift), and it is what the libraries our
  users know (scikit-learn, scikit-image, MNE, GUDHI) build their sites with.
* **numpydoc** because every public docstring is written in the NumPy format
  (Parameters / Returns / Raises / Examples sections); numpydoc renders those sections.
* **sphinx-gallery** because it *runs* every ``examples/plot_*.py`` and puts the script,
  its output and its figures on one page: an example that breaks breaks the build.
* The **command-line reference** is generated at build time by a small extension of
  ours (``docs/_ext/cli_reference.py``) that walks ``cyclecoord.cli``'s argparse parsers,
  so it is always the ``--help`` the installed command prints.

The build is nitpicky: a cross-reference that resolves nowhere is a warning, and
``-W`` makes every warning an error.  Types from other libraries (NumPy, matplotlib,
the standard library) are not linked (no intersphinx: the build needs no network) and
are listed in ``nitpick_ignore_regex`` below.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(ROOT / "src"))  # the checkout's package, installed or not

os.environ.setdefault("MPLBACKEND", "Agg")

import cyclecoord  # noqa: E402

project = "cyclecoord"
author = "cyclecoord developers"
copyright = "cyclecoord developers, MIT licence"
version = release = cyclecoord.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "cli_reference",
]

root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "auto_examples/*.ipynb",
                    "auto_examples/*.py", "auto_examples/*.zip", "auto_examples/*.md5",
                    "auto_examples/*.json"]
templates_path = ["_templates"]
nitpicky = True

# ------------------------------------------------------------------ API reference
autosummary_generate = True
# autosummary writes a page per module into generated/ but never removes one: a module
# moved or renamed since the last build would leave a page that no longer imports (a
# warning, so a failed -W build), so every build starts from an empty folder
import shutil  # noqa: E402

shutil.rmtree(Path(__file__).resolve().parent / "generated", ignore_errors=True)
autosummary_imported_members = False
autodoc_default_options = {"members": True, "inherited-members": False}
autodoc_typehints = "none"  # the numpydoc sections give the types, in words
autodoc_member_order = "bysource"
autoclass_content = "class"

numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_attributes_as_param_list = True

# Names that are not ours and are not linked (no intersphinx: the build is offline), and
# informal type words of the numpydoc sections.
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|scipy|sklearn|matplotlib|mpl|networkx|nx|plotly|pandas|dask"
               r"|distributed|pxr|pygltflib|tqdm|gudhi|ripser)(\..*)?"),
    (r"py:.*", r"(os|pathlib|typing|collections|collections\.abc|argparse|io|json|enum"
               r"|dataclasses|concurrent\.futures|types|abc|contextlib)\..*"),
    (r"py:(func|class|mod|exc)", r"(repr|open|str|int|float|bool|list|dict|tuple|set|object"
                                  r"|multiprocessing|Exception|ValueError|KeyboardInterrupt)"),
    (r"py:.*", r"(Path|PathLike|ArrayLike|NDArray|Axes|Figure|Iterable|Iterator|Sequence"
               r"|Mapping|Callable|Any|Literal|Self|Generator|DiGraph|Graph)"),
]

# ------------------------------------------------------------------ gallery
# Only examples/plot_*.py are run (each makes a figure); the other scripts in examples/
# are command-line tools shown as code.  CYCLECOORD_DOCS_GALLERY=0 builds the gallery
# pages without running them (the test suite does this to stay fast).
_run_gallery = os.environ.get("CYCLECOORD_DOCS_GALLERY", "1") != "0"
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"__init__\.py",
    "plot_gallery": "True" if _run_gallery else "False",
    "download_all_examples": False,
    "within_subsection_order": "FileNameSortKey",
    "remove_config_comments": True,
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
    "min_reported_time": 1,
    "show_memory": False,
    "backreferences_dir": None,
    "write_computation_times": False,
    # CYCLECOORD_DOCS_RERUN=1 runs every example even when unchanged since the last build
    "run_stale_examples": os.environ.get("CYCLECOORD_DOCS_RERUN", "0") == "1",
}

# ------------------------------------------------------------------ HTML
html_theme = "pydata_sphinx_theme"
html_title = "cyclecoord"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}
html_show_sourcelink = False


# ------------------------------------------------------------------ cross-references
def _locate(target: str, module: str | None, cls: str | None):
    """``(object, dotted path)`` that ``target`` names, read as Python reads it in
    ``module`` (and class ``cls``), or ``(None, None)`` when it names nothing."""
    import importlib

    def walk(obj, parts):
        for part in parts:
            try:
                obj = getattr(obj, part)
            except Exception:
                return None
        return obj

    if target.startswith("cyclecoord"):
        parts = target.split(".")
        for k in range(len(parts), 0, -1):
            try:
                mod = importlib.import_module(".".join(parts[:k]))
            except Exception:
                continue
            found = walk(mod, parts[k:])
            return (found, target) if found is not None else (None, None)
    if module:
        try:
            mod = importlib.import_module(module)
        except Exception:
            return None, None
        for prefix in ([cls] if cls else []) + [None]:
            parts = (prefix.split(".") if prefix else []) + target.split(".")
            found = walk(mod, parts)
            if found is not None:
                return found, ".".join([module, *parts])
    return None, None


def _canonical(obj) -> str | None:
    import types

    if isinstance(obj, types.ModuleType):
        return obj.__name__
    module, qualname = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
    if isinstance(module, str) and isinstance(qualname, str) and module.startswith("cyclecoord"):
        return f"{module}.{qualname}"
    return None


def _resolve_alias(app, env, node, contnode):
    """Resolve a reference the way Python resolves the name.

    A name re-exported elsewhere (``cyclecoord.extract``, or ``extract`` imported into a
    module) links to where it is documented; an attribute, a constant or a private helper
    that exists but has no entry of its own links to its class or module.  A name that
    does not exist stays unresolved, which is a warning (the build is nitpicky, and
    ``-W`` makes it an error).
    """
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip("~.")
    module, cls = node.get("py:module"), node.get("py:class")
    domain = env.get_domain("py")

    def link(name: str):
        return domain.resolve_xref(env, node["refdoc"], app.builder, "obj", name, node,
                                   contnode)

    obj, path = _locate(target, module, cls)
    if obj is not None:
        candidates = [c for c in (_canonical(obj), path) if c and c != target]
        parts = path.split(".")
        candidates += [".".join(parts[:k]) for k in range(len(parts) - 1, 0, -1)]
        for name in candidates:
            ref = link(name)
            if ref is not None:
                return ref
        return None
    # Not a name of the module the docstring is in: a name of the package that only one
    # documented object (or, for Owner.attribute, one documented class whose docstring
    # describes that attribute) carries.
    *owner, last = target.split(".")
    if cls and not owner and _describes(f"{module}.{cls}", last):
        return link(f"{module}.{cls}")
    if owner:  # Owner.field: a dataclass field or an attribute its docstring describes
        holder, _ = _locate(".".join(owner), module, cls)
        name = _canonical(holder) if holder is not None else None
        if name and _describes(name, last):
            return link(name)
    kinds = set(domain.objtypes_for_role(node["reftype"]) or ())
    matches = [n for n, entry in domain.objects.items()
               if (n == target or n.endswith("." + target))
               and (not kinds or entry.objtype in kinds)]
    if len(matches) == 1:
        return link(matches[0])
    if owner:
        holders = [n for n in domain.objects
                   if (n == ".".join(owner) or n.endswith("." + ".".join(owner)))
                   and _describes(n, last)]
        if len(holders) == 1:
            return link(holders[0])
    return None


def _describes(dotted: str, attribute: str) -> bool:
    """Whether the class ``dotted`` has ``attribute``, a field of that name or describes
    it in its docstring (an estimator's fitted ``root_``)."""
    import inspect
    import re

    obj, _ = _locate(dotted, None, None)
    if not inspect.isclass(obj):
        return False
    if hasattr(obj, attribute) or attribute in getattr(obj, "__annotations__", {}):
        return True
    doc = inspect.getdoc(obj) or ""
    return re.search(rf"^\s*{re.escape(attribute)}\s*:", doc, flags=re.MULTILINE) is not None


def _skip_imported(app, what, name, obj, skip, options):
    """A module documents what it defines: a function or class a package re-exports in
    its ``__all__`` is documented once, in the module it comes from."""
    import inspect

    if what == "module" and (inspect.isfunction(obj) or inspect.isclass(obj)):
        owner = app.env.temp_data.get("autodoc:module")
        if owner and getattr(obj, "__module__", owner) != owner:
            return True
    return None


def setup(app):
    app.connect("missing-reference", _resolve_alias)
    app.connect("autodoc-skip-member", _skip_imported)
