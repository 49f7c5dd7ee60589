"""The framework wing: what a module author meets. Representations (``representation.py``: plain data
classes with defaults, ranges and a registry by name; ``frame_info.py``: the frame clock the runtime
writes), modules and their declarations (``module.py``),
read-only and writing views of the blackboard (``access.py``), the module manager and its blackboard
(``manager.py``, ordering by ``graph.py``), parameters and the checking of every value a client or a
file sets (``parameters.py``, ``validation.py``, ``values.py``), the contexts (``contexts.py``), configuration (``config.py``), modules from folders
and packages of one's own (``extensions.py``), hot reload (``reload.py``), names and errors."""
