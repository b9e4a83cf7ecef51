// The session's recording report: the command that makes it from a shell (with this session's real
// recording), and a button that has the server make it now (in a child process) and links its files.
import { api, el } from "./common.js";

export class ReportPanel {
  constructor(root) {
    this.how = root.querySelector("#report-how");
    this.button = root.querySelector("#report-make");
    this.result = root.querySelector("#report-result");
    this.button.addEventListener("click", () => this.make());
    this.load();
  }

  async load() {
    try { this.describe(await api("/api/report")); } catch (error) { this.how.textContent = `report: ${error.message}`; }
  }

  describe(info) {
    if (!info.command) {
      this.how.textContent = "This session records nothing (run.record=false), so there is no report.";
      this.button.disabled = true;
      return;
    }
    this.how.replaceChildren("From a shell, any time (also after the session): ",
      el("code", { class: "report-command", text: info.command }));
  }

  async make() {
    this.button.disabled = true;
    this.result.className = "small muted";
    this.result.textContent = "making the report (a child process reads the recording)…";
    const started = performance.now();
    try {
      const report = await api("/api/report", {});
      const seconds = ((performance.now() - started) / 1000).toFixed(1);
      const link = (name) => el("a", { href: `/api/report/${encodeURIComponent(name)}`, target: "_blank", text: name });
      this.result.className = "small";
      this.result.replaceChildren(
        el("div", { text: `made in ${seconds} s: ` }, link("results.md")),
        el("ul", { class: "list report-files" }, report.figures.map((name) => el("li", {}, link(name)))));
    } catch (error) {
      this.result.className = "small late";
      this.result.textContent = `no report: ${error.message}`;
    } finally { this.button.disabled = false; }
  }
}
