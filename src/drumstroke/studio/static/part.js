// The part view.
import {el} from "./common.js";

export function build(section) {
  section.append(el("h2", {}, "part"), el("p", {}, "Not built yet."));
}
