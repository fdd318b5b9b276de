"""python -m autograder roster|release|collect|grade|feedback|export COURSE_DIR, record-answers: the
instructor's commands; release-lab: the assignments for a student's `make lab`; grade-lab: grades
what that student submitted there and releases the feedback for Fetch Feedback."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m autograder", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    ros = sub.add_parser("roster", help="students (id, first_name, last_name, email) from a CSV into the gradebook")
    ros.add_argument("course_dir", type=Path)
    ros.add_argument("roster", type=Path)
    rel = sub.add_parser("release", help="write the student versions to COURSE_DIR/release/<assignment>/")
    rel.add_argument("course_dir", type=Path)
    rel.add_argument("--assignment", action="append", help="only this assignment (repeatable)")
    rel.add_argument("--duedate", help='due date of the assignment(s), e.g. "2025-03-14 23:59 Europe/Berlin"')
    lab = sub.add_parser("release-lab", help="release the assignments into the exchange of `make lab` "
                         "(.lab/ in LAB_ROOT, default this repository), where a student alone fetches them")
    lab.add_argument("lab_root", type=Path, nargs="?", default=None)
    gla = sub.add_parser("grade-lab", help="grade the latest submission of each assignment in the exchange of "
                         "`make lab` and release its feedback (Fetch Feedback in Nbgrader > Assignment List)")
    gla.add_argument("lab_root", type=Path, nargs="?", default=None)
    gla.add_argument("--assignment", action="append", help="only this assignment (repeatable)")
    col = sub.add_parser("collect", help="an LMS download (zip) of an assignment into COURSE_DIR/submitted/")
    col.add_argument("course_dir", type=Path)
    col.add_argument("assignment")
    col.add_argument("archives", type=Path, nargs="+", help="the downloaded .zip files (or notebooks)")
    gra = sub.add_parser("grade", help="autograde COURSE_DIR/submitted/<student>/<assignment>/ in the sandbox")
    gra.add_argument("course_dir", type=Path)
    gra.add_argument("--assignment", help="only this assignment")
    gra.add_argument("--student", help="only this student")
    gra.add_argument("--workers", type=int, default=1, help="submissions graded at the same time (default 1)")
    gra.add_argument("--force", action="store_true", help="grade again submissions that did not change")
    fee = sub.add_parser("feedback", help="write per-student HTML feedback to COURSE_DIR/feedback/")
    fee.add_argument("course_dir", type=Path)
    fee.add_argument("--assignment", help="only this assignment")
    fee.add_argument("--student", help="only this student")
    exp = sub.add_parser("export", help="COURSE_DIR/grades.csv for the LMS: final scores, late penalty applied")
    exp.add_argument("course_dir", type=Path)
    rec = sub.add_parser("record-answers", help="record the self-checks' answers from the grader's answer keys "
                         "(after changing a check's inputs or an answer key)")
    rec.add_argument("assignments", nargs="*", help="default: every assignment with an answer key")
    return parser


def main(argv=None) -> int:
    from autograder import nbgrader_cli

    nbgrader_cli.import_without_server_extensions()  # the commands use nbgrader's steps, never its server
    parser = _parser()
    args = parser.parse_args(argv)
    try:
        return _run(parser, args)
    except (ValueError, FileNotFoundError) as error:  # bad input: the message names the fix
        print(f"python -m autograder {args.command}: {error}", file=sys.stderr)
        return 2


def _run(parser, args) -> int:
    if args.command == "record-answers":
        from autograder.term import record_answers

        for path in record_answers.record_answers(args.assignments or None):
            print(path)
        return 0
    from autograder.term import grade, release

    if args.command == "roster":
        from autograder.term import roster

        release.prepare_course(args.course_dir)
        count, ignored = roster.import_roster(args.course_dir, args.roster)
        print(f"{count} students in the gradebook" + (f" (columns ignored: {', '.join(ignored)})" if ignored else ""))
    elif args.command == "release":
        for path in release.release(args.course_dir, args.assignment, duedate=args.duedate):
            print(path)
    elif args.command == "release-lab":
        released = release.release_for_lab(*([args.lab_root] if args.lab_root else []))
        print(f"Released for Nbgrader > Assignment List: {', '.join(released)}" if released
              else "The assignments in Nbgrader > Assignment List are up to date")
    elif args.command == "grade-lab":
        from autograder.term import lab_grading

        results = lab_grading.grade_lab(*([args.lab_root] if args.lab_root else []), assignments=args.assignment)
        print("\n".join(map(lab_grading.summary, results)) or "Nothing submitted yet: press Submit in "
              "Nbgrader > Assignment List first")
    elif args.command == "collect":
        from autograder.term import collect

        print("\n".join(collect.collect(args.course_dir, args.assignment, args.archives)))
    elif args.command == "grade":
        if args.workers < 1:
            parser.error("--workers must be at least 1")
        from autograder.grading import work_folders

        swept = work_folders.sweep()  # what the gradings of a killed grade run (or service) left
        if swept:
            print(f"Removed {len(swept)} work folder(s) of gradings cut short", file=sys.stderr)
        results = grade.grade(args.course_dir, args.assignment, workers=args.workers, force=args.force,
                                student=args.student)
        failed = [r for r in results if r.status == "failed"]
        course = Path(args.course_dir)
        print(f"{len(results)} submissions, {len(failed)} not graded; report in {course / 'grading_report.csv'}, "
              f"final scores for the LMS in {course / 'grades.csv'}")
    elif args.command == "feedback":
        from autograder.term import feedback

        for path in feedback.write_feedback(args.course_dir, args.assignment, args.student):
            print(path)
    else:
        from autograder.term import export

        print(export.export(args.course_dir))
    return 0


if __name__ == "__main__":
    sys.exit(main())
