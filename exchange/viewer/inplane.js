// The in-plane plot's control on the page weft export -o X.html and weft view write
// (exchange/src/preview_html.cpp inlines it as a classic script, so that the curves switch even
// where the 3-D view's modules or WebGL fail): every incidence is drawn in the SVG, one shown at a
// time; the slider picks it, and so does a link to the page ending in #incidence=DEG (the drawn
// incidence nearest DEG), which the slider keeps up to date.
(() => {
  const input = document.getElementById('weft-incidence');
  const value = document.getElementById('weft-incidence-value');
  const groups = Array.from(document.querySelectorAll('#weft-inplane g.weft-incidence'));
  if (!input || groups.length === 0) return;
  const angles = groups.map((g) => Number(g.dataset.incidence));

  function show(index) {
    groups.forEach((g, k) => g.setAttribute('display', k === index ? 'inline' : 'none'));
    input.value = String(index);
    value.textContent = angles[index] + '\u00b0';
    document.body.dataset.weftIncidence = String(angles[index]);
  }
  function fromHash() {
    const m = /incidence=([0-9.]+)/.exec(window.location.hash);
    if (!m) return false;
    const want = Number(m[1]);
    let best = 0;
    angles.forEach((a, k) => {
      if (Math.abs(a - want) < Math.abs(angles[best] - want)) best = k;
    });
    show(best);
    return true;
  }

  input.addEventListener('input', () => {
    const index = Number(input.value);
    show(index);
    // The address names the incidence shown, so that a copied link shows it too; a browser that
    // refuses to change a file: URL's history leaves the address as it is.
    try {
      window.history.replaceState(null, '', '#incidence=' + angles[index]);
    } catch (error) {}
  });
  window.addEventListener('hashchange', fromHash);
  if (!fromHash()) show(Number(input.value) || 0);
})();
