"""Frames to files: PNG images and the video writer (MP4, WebM, GIF, PNG sequences)."""
