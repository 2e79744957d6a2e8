// The pair page: each stimulus played is recorded by the server; the answer can be sent once both are,
// and one click sends it once. Served as a file, so the Content-Security-Policy needs no inline script.
"use strict";

const form = document.getElementById("answer-form");
const submit = document.getElementById("submit");
const played = new Set();

for (const side of ["A", "B"]) {
  document.getElementById("audio-" + side).addEventListener("play", () => {
    const body = new URLSearchParams({side: side, csrf: form.elements.csrf.value});
    fetch(form.dataset.played, {method: "POST", body: body}).then((response) => {
      if (!response.ok) {
        return;
      }
      played.add(side);
      if (played.size === 2) {
        submit.disabled = false;
        document.getElementById("hint").textContent = "";
      }
    });
  });
}

form.addEventListener("submit", () => {
  submit.disabled = true;  // one click, one answer
});
