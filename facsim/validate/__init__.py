"""The closed loop: render known expressions, read them back, report per AU."""
