// Pose Studio's library actions: save the draft, perform it on the robot, rename or delete the opened
// motion. The server applies the library's checks (name pattern, overwrite, the rest pose, a class's
// last motion, a backup of every replaced or removed file); the page shows its answer.
import { api, intensityWords } from "./common.js";

const $ = (id) => document.getElementById(id);

function say(id, ok, text) { $(id).className = ok ? "ok" : "bad"; $(id).textContent = text; }

// `page`: draft() (the request body), motion() (the save body), opened() (the library name on screen),
// and after(name, saved) (reload the library; saved: the screen now matches the library).
export function wireLibraryActions(page) {
  $("save").onclick = async () => {
    try {
      const saved = await api("/api/library", { ...page.motion(), overwrite: $("overwrite").checked });
      say("save-result", true, `saved ${saved.name} → ${saved.file}` + (saved.backup ? ` (backup ${saved.backup})` : "")
        + ` · library v${saved.version}: the planner and resolver see it now`);
      await page.after(saved.name, true);
    } catch (error) { say("save-result", false, error.message); }
  };
  // The keyframes on screen (saved or not) through the same checks as any gesture; the library is unchanged.
  $("perform").onclick = async () => {
    try {
      const turn = await api("/api/studio/perform", { ...page.draft(), class: $("class").value });
      const cue = turn.cues[0];
      if (cue.outcome) { say("perform-result", false, `not performed: ${cue.outcome.reason}`); return; }
      say("perform-result", true, `performing the draft on screen at ${intensityWords(cue)}`
        + ` (as ${cue.resolved}; the library is unchanged)`);
    } catch (error) { say("perform-result", false, error.message); }
  };
  $("rename").onclick = async () => {
    const name = page.opened(), newName = prompt(`New name for ${name}:`, name);
    if (!newName || newName === name) return;
    try {
      const saved = await api(`/api/library/${encodeURIComponent(name)}/rename`, { new_name: newName });
      say("library-result", true, `renamed ${name} → ${saved.name} (old file kept in ${saved.backup})`);
      $("name").value = saved.name;
      await page.after(saved.name, true);
    } catch (error) { say("library-result", false, error.message); }
  };
  $("delete").onclick = async () => {
    const name = page.opened();
    if (!confirm(`Delete ${name} from the library? (its file is kept in .backup/)`)) return;
    try {
      const answer = await api(`/api/library/${encodeURIComponent(name)}/delete`, {});
      say("library-result", true, `deleted ${name} (file kept in ${answer.backup}); the draft stays on screen`);
      await page.after(null, false);
    } catch (error) { say("library-result", false, error.message); }
  };
}
