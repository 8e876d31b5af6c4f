"""See a robot YAML: a PNG sheet of its frames (``sheet``) and a browser viewer (``server``)."""
