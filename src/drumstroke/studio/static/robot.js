// The robot view.
import {el} from "./common.js";

export function build(section) {
  section.append(el("h2", {}, "robot"), el("p", {}, "Not built yet."));
}
