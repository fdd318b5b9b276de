/* The student lab's Validate on a lesson (course_lib/notebook/student_lab/validate.py answers it
 * without running the lesson): nbgrader shows every answer that is no validation under its heading
 * "There was an error running the validate command:", but a lesson did nothing wrong. When Validate
 * was pressed on a notebook without nbgrader cells, this extension makes the answer's first line
 * (validate.LESSON_HEADING) the dialog's heading, and gives the dialog nbgrader's look of a success.
 *
 * Written by hand as a module-federation container, as validate-progress beside it is.
 */
(function () {
  "use strict";

  const NAME = "@course-lib/validate-lesson";
  const BUTTON = ".validate-button";
  // validate.is_assignment: some cell's nbgrader metadata grades, holds a solution or a task, or locks.
  const ASSIGNMENT_KEYS = ["grade", "solution", "task", "locked"];
  // Validate on a lesson answers at once; after this long a dialog is another press's.
  const WAIT_MS = 60000;

  function isLesson(model) {
    return !(model.toJSON().cells || []).some((cell) => {
      const meta = (cell.metadata || {}).nbgrader || {};
      return ASSIGNMENT_KEYS.some((key) => meta[key]);
    });
  }

  // nbgrader's error answer: #validation-message holds <div><p>heading</p></div><pre>answer</pre>,
  // and no class "validation-..." (those mark a validation that ran).
  function retitle(message) {
    const heading = message.querySelector(":scope > div > p");
    const answer = message.querySelector(":scope > pre");
    const ran = [...message.classList].some((name) => name.startsWith("validation-"));
    if (!heading || !answer || ran) return;
    // nbgrader set the answer as innerText: each line break became a <br>.
    const lines = [""];
    for (const node of answer.childNodes) {
      if (node.nodeName === "BR") lines.push("");
      else lines[lines.length - 1] += node.textContent;
    }
    heading.innerText = lines[0];
    answer.innerText = lines.slice(1).join("\n");
    message.classList.add("validation-lesson");
    const dialog = message.closest(".jp-Dialog");
    if (dialog) {
      dialog.classList.replace("nbgrader-ErrorDialog", "nbgrader-SuccessDialog");
    }
  }

  function retitleNextAnswer() {
    let timer = null;
    const observer = new MutationObserver(() => {
      const message = document.getElementById("validation-message");
      if (!message) return;
      observer.disconnect();
      clearTimeout(timer);
      retitle(message);
    });
    observer.observe(document.body, { childList: true, subtree: true });
    timer = setTimeout(() => observer.disconnect(), WAIT_MS);
  }

  const plugin = {
    id: NAME + ":plugin",
    description: "Shows Validate's answer on a lesson under its own heading, not nbgrader's error heading.",
    autoStart: true,
    activate(app) {
      document.addEventListener("click", (event) => {
        const button = event.target instanceof Element ? event.target.closest(BUTTON) : null;
        if (!button) return;
        const panel = Array.from(app.shell.widgets("main")).find((widget) => widget.node.contains(button));
        if (panel && panel.context && panel.context.model && isLesson(panel.context.model)) retitleNextAnswer();
      }, true);
    },
  };

  window._JUPYTERLAB = window._JUPYTERLAB || {};
  window._JUPYTERLAB[NAME] = {
    init: () => Promise.resolve(),
    get: (module) => module === "./extension"
      ? Promise.resolve(() => ({ __esModule: true, default: plugin }))
      : Promise.reject(new Error(`${NAME} has no module ${module}`)),
  };
})();
