"""The application layer: design files, the ``spiral-cad`` command and its plots."""
