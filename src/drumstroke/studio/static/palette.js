// The palette view.
import {el} from "./common.js";

export function build(section) {
  section.append(el("h2", {}, "palette"), el("p", {}, "Not built yet."));
}
