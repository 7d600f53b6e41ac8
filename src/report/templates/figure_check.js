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
  // Where the figures and tables were laid out (CSS pixels from the page's top left), and the
  // page's size, for a screenshot test to look at those places.
  var box = function (e) {
    var r = e.getBoundingClientRect();
    return [r.left + window.scrollX, r.top + window.scrollY, r.width, r.height]
      .map(function (v) { return Math.round(v); }).join(',');
  };
  var boxes = function (list) { return Array.prototype.map.call(list, box).join(' '); };
  el.setAttribute('data-figure-boxes', boxes(imgs));
  el.setAttribute('data-table-boxes', boxes(document.querySelectorAll('table')));
  var d = document.documentElement;
  el.setAttribute('data-page', d.scrollWidth + ',' + d.scrollHeight);
});
