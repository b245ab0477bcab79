// MathJax 3 reads only what pymdownx.arithmatex (generic mode) wrapped in
// <span class="arithmatex"> or <div class="arithmatex">, as \( \) and \[ \].
window.MathJax = {
  tex: {
    inlineMath: [["\\(", "\\)"]],
    displayMath: [["\\[", "\\]"]],
    processEscapes: true,
    processEnvironments: true
  },
  options: {
    ignoreHtmlClass: ".*|",
    processHtmlClass: "arithmatex"
  }
};
