"""Action units over time: the data model, its sampling per frame, builders, easing, files and plots."""
