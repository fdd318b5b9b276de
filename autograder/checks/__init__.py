"""One module per assignment; each holds that assignment's graded checks (see autograder.harness)."""
