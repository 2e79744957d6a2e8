// The designer view.
import {el} from "./common.js";

export function build(section) {
  section.append(el("h2", {}, "designer"), el("p", {}, "Not built yet."));
}
