"""Motion generation: trajectory timing and following, reactive target following (``reactive``),
target motions (``targets``)."""
