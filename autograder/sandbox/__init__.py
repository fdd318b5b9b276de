"""What keeps a submission's code from the grader, the course and other students: namespaces, uids,
the graded kernel and its cells' limits, and student files read without following them out."""
