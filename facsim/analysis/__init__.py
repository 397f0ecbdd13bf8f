"""The camera processor (Platt & Badler Fig. 1): images and video of faces → FACS."""
