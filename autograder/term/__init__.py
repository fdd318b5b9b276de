"""The term's commands over a course directory (``python -m autograder ...``): roster, release, collect,
grade, feedback, export and record-answers, with the due dates and late penalties they share."""
