"""Every ``matshop`` verb: its name, its one-line summary and the module that does it.

In the spirit of pip's ``commands_dict``: ``matshop --help`` lists the verbs from
this table without importing any of them, and a command line imports only the
module of the verb it names. A verb module has ``add_arguments(parser)``, which
adds the verb's options (and may set the parser's description and epilog) and
sets ``run`` (a function ``(args) -> int``) as a parser default; a verb with
actions (``layer add``, ``layer set``) sets it on each action's parser. So
:func:`matshop.cli.main` always dispatches the same way: ``args.run(args)``.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from types import ModuleType


@dataclass(frozen=True)
class Verb:
    module: str
    summary: str


_V = "matshop.cli.verbs."

#: name -> verb, in the order ``matshop --help`` lists them
VERBS: dict[str, Verb] = {
    "info": Verb(_V + "info", "show the parameters, sizes and encodings of a texture set"),
    "convert": Verb(
        _V + "convert", "import a texture set, convert to edit space and back, write it"
    ),
    "apply": Verb(_V + "apply", "apply image operations in edit space and write the result"),
    "ops": Verb(_V + "ops", "list the operations and their parameters"),
    "spaces": Verb(_V + "spaces", "list the editing spaces"),
    "demo": Verb(_V + "demo", "run the main job on the bundled sample material"),
    "export": Verb(
        _V + "export", "write a texture set for an engine (Unreal, Unity, glTF, Godot, raw)"
    ),
    "render": Verb(_V + "render", "render a texture set on a sphere, a swatch or a mesh (PNG)"),
    "figures": Verb(_V + "figures", "reproduce the seed paper's figures with their measurements"),
    "new": Verb(_V + "new", "create a .matshop project (from a texture set, or empty)"),
    "layer": Verb(_V + "layer", "add, list, change or remove layers of a project"),
    "paint": Verb(_V + "paint", "paint brush strokes from a JSON file into a project"),
    "recover": Verb(_V + "recover", "restore a project from its autosave (recovery) file"),
    "flatten": Verb(_V + "flatten", "flatten a project and write it as a texture set"),
    "batch": Verb(_V + "batch", "apply a recipe to every texture set of a library, on Dask"),
    "warm-up": Verb(
        _V + "warm_up", "compile the numba kernels now, so first uses in the editor do not"
    ),
    "open": Verb(
        _V + "open",
        "start the editor (optionally opening a texture set or a .matshop project)",
    ),
}


def load(name: str) -> ModuleType:
    """The module of the verb ``name`` (imported now, not when ``matshop`` starts)."""
    return importlib.import_module(VERBS[name].module)
