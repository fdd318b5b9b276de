"""The tests' helpers, one module per job: a browser and JupyterLab (browser, browser_notebook,
browser_nbgrader), a released course (course), the hub (hub), processes (process), a submission zoo
(zoo), the lessons' answers (lesson_answers), ... pyproject.toml's ``pythonpath`` puts tests/ on
sys.path, so a test imports them as ``from support.process import wait_until``."""
