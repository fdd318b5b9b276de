"""python -m autograder release|grade|feedback COURSE_DIR, record-answers: the instructor's commands."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m autograder", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    rel = sub.add_parser("release", help="write the student versions to COURSE_DIR/release/<assignment>/")
    rel.add_argument("course_dir", type=Path)
    rel.add_argument("--assignment", action="append", help="only this assignment (repeatable)")
    gra = sub.add_parser("grade", help="autograde COURSE_DIR/submitted/<student>/<assignment>/ and write grades.csv")
    gra.add_argument("course_dir", type=Path)
    gra.add_argument("--assignment", help="only this assignment")
    gra.add_argument("--workers", type=int, default=1, help="submissions graded at the same time (default 1)")
    gra.add_argument("--force", action="store_true", help="grade again submissions that did not change")
    fee = sub.add_parser("feedback", help="write per-student HTML feedback to COURSE_DIR/feedback/")
    fee.add_argument("course_dir", type=Path)
    fee.add_argument("--assignment", help="only this assignment")
    rec = sub.add_parser("record-answers", help="record the self-checks' answers from the grader's answer keys "
                         "(after changing a check's inputs or an answer key)")
    rec.add_argument("assignments", nargs="*", help="default: every assignment with an answer key")
    args = parser.parse_args(argv)

    if args.command == "record-answers":
        from autograder import record

        for path in record.record_answers(args.assignments or None):
            print(path)
        return 0
    from autograder import grading

    if args.command == "release":
        for path in grading.release(args.course_dir, args.assignment):
            print(path)
        return 0
    if args.command == "grade":
        if args.workers < 1:
            parser.error("--workers must be at least 1")
        results = grading.grade(args.course_dir, args.assignment, workers=args.workers, force=args.force)
        failed = [r for r in results if r.status == "failed"]
        print(f"{len(results)} submissions, {len(failed)} failed to run; grades in {Path(args.course_dir) / 'grades.csv'}")
        return 0
    from autograder import feedback

    for path in feedback.write_feedback(args.course_dir, args.assignment):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
