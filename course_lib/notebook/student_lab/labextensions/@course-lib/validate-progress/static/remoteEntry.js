/* The student lab's Validate progress (course_lib/notebook/student_lab/validate_progress.py is the server
 * side): while nbgrader's Validate runs an assignment, its button says what runs, once a second:
 * "Validating: starting the kernel", "Validating: cell 7 of 23", "Validating: reading the results",
 * and its tooltip the first line of that cell. A cell that may run long says what it does first:
 * "Validating: building the workspace (colcon), cell 11 of 14".
 *
 * Written by hand as the module-federation container JupyterLab loads for an extension (an object
 * with get and init in window._JUPYTERLAB): the plugin imports no JupyterLab module, so it needs
 * no build. It reads the label nbgrader's button shows and writes it as nbgrader does (innerText
 * of the label), only while nbgrader's own label says "Validating".
 */
(function () {
  "use strict";

  const NAME = "@course-lib/validate-progress";
  const PROGRESS_URL = "course-lib/validate-progress";
  const BUTTON = ".validate-button";
  const LABEL = ".jp-ToolbarButtonComponent-label";
  // After the click nbgrader checks its version and saves ("Saving...") before "Validating...".
  const TICKS_BEFORE_VALIDATING = 30;

  function said(step) {
    if (step.cell === 0) return "Validating: starting the kernel";
    const where = step.doing ? `${step.doing}, cell ${step.cell}` : `cell ${step.cell}`;
    if (step.cell >= step.cells) return `Validating: ${where} of ${step.cells}, then the results`;
    return `Validating: ${where} of ${step.cells}`;
  }

  const followed = new WeakSet();

  async function follow(app, button, path) {
    const settings = app.serviceManager.serverSettings;
    const url = settings.baseUrl + PROGRESS_URL + "?path=" + encodeURIComponent(path);
    const headers = settings.token ? { Authorization: "token " + settings.token } : {};
    const label = () => button.querySelector(LABEL);
    const shown = () => (label() ? label().innerText.trim() : "");
    followed.add(button);
    try {
      for (let tick = 0, validating = false; ; tick++) {
        await new Promise((resolve) => setTimeout(resolve, 1000));
        if (shown().startsWith("Validating")) {
          validating = true;
        } else if (validating || tick >= TICKS_BEFORE_VALIDATING) {
          return; // nbgrader answered (its label is "Validate" again), or never began
        } else {
          continue;
        }
        let step;
        try {
          const response = await fetch(url, { headers, credentials: "same-origin" });
          step = await response.json();
        } catch (error) {
          continue; // the server is busy or restarting: nbgrader's own label stays
        }
        if (step.running && shown().startsWith("Validating")) {
          label().innerText = said(step);
          label().title = step.line ? `cell ${step.cell} of ${step.cells}: ${step.line}` : "";
        }
      }
    } finally {
      if (label()) label().title = "";
      followed.delete(button);
    }
  }

  const plugin = {
    id: NAME + ":plugin",
    description: "Says on nbgrader's Validate button which cell the validation runs.",
    autoStart: true,
    activate(app) {
      document.addEventListener("click", (event) => {
        const button = event.target instanceof Element ? event.target.closest(BUTTON) : null;
        if (!button || followed.has(button)) return;
        const panel = Array.from(app.shell.widgets("main")).find((widget) => widget.node.contains(button));
        if (panel && panel.context) void follow(app, button, panel.context.path);
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
