"""What was handed in and what its grading recorded: the submissions, each one's result, the store of
results, the course gradebook and the grading report."""
