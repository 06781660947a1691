"""Caving streams as scene input: the particle generator (``tailbeam.streams.generator``)."""
