window.addEventListener('load', function () {
  var imgs = document.querySelectorAll('img.figure');
  var broken = [];
  for (var i = 0; i < imgs.length; i++) {
    var m = imgs[i];
    if (!(m.complete && m.naturalWidth > 0 && m.naturalHeight > 0)) {
      broken.push(m.getAttribute('src'));
    }
  }
  var el = document.getElementById('figure-check');
  el.setAttribute('data-total', String(imgs.length));
  el.setAttribute('data-loaded', String(imgs.length - broken.length));
  el.setAttribute('data-broken', broken.join(' '));
  el.setAttribute('data-status', broken.length ? 'broken' : 'ok');
  el.className = broken.length ? 'warn' : 'ok';
  el.textContent = 'Figure check (in this browser): ' + (imgs.length - broken.length) + ' of ' +
    imgs.length + ' figures loaded' + (broken.length ? '; broken: ' + broken.join(', ') : '.');
});
