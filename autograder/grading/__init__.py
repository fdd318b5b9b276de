"""Grading one submission, step by step: its intake, private copies and work folder, the notebook's
run with the checks that start early, the hidden checks, and what it leaves in the course."""
