"""Sub-commands of the ``tailbeam`` CLI, one module each."""
