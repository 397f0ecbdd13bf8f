"""Closed-loop validation of the camera processor against facsim's own renders (``facsim validate``)."""
