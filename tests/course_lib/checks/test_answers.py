"""Where a check's expected answers come from (course_lib.checks.answers): the answer key the grader
hands over through the contract when graded, the recorded answers in a self-check."""

import json

import numpy as np
import pytest

from autograder import answers as answer_keys
from course_lib import contract
from course_lib.checks import answers
from course_lib.checks.student_processes import student_env


def test_a_graded_check_reads_the_key_from_the_folder_the_grader_hands_over(tmp_path, monkeypatch):
    (tmp_path / "demo.py").write_text("def double(x):\n    return 2 * int(x)\n")
    monkeypatch.setenv(contract.ANSWER_KEYS_ENV, str(tmp_path))
    assert answers.AnswerKey("demo", "graded").expected("double", 21) == 42


def test_without_a_key_a_graded_check_names_the_variable(monkeypatch):
    monkeypatch.delenv(contract.ANSWER_KEYS_ENV, raising=False)
    with pytest.raises(RuntimeError, match=contract.ANSWER_KEYS_ENV):
        answers.AnswerKey("brightness", "graded").expected("average_brightness", np.zeros((2, 2), np.uint8))


def test_the_grader_hands_over_its_own_answer_keys():
    folder = answer_keys.environment()[contract.ANSWER_KEYS_ENV]
    assert folder == str(answer_keys.FOLDER) and (answer_keys.FOLDER / "brightness.py").is_file()


def test_student_processes_never_get_the_answer_keys():
    assert student_env()[contract.ANSWER_KEYS_ENV] is None


def test_a_recording_writes_each_answer_it_gives(tmp_path, monkeypatch):
    monkeypatch.setenv(contract.RECORD_ANSWERS_ENV, str(tmp_path / "lines.jsonl"))
    image = np.full((2, 3), 7, np.uint8)
    assert answers.AnswerKey("brightness", "record").expected("average_brightness", image) == 7
    entry = json.loads((tmp_path / "lines.jsonl").read_text())
    assert entry == {"assignment": "brightness", "question": "average_brightness",
                     "key": answers.input_key(image), "answer": 7}


def test_a_selfcheck_without_a_recorded_answer_says_to_record_again():
    with pytest.raises(answers.MissingAnswer, match="record-answers brightness"):
        answers.AnswerKey("brightness", "selfcheck").expected("average_brightness", np.full((1, 1), 3, np.uint8))
