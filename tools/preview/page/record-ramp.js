// The records view's colours for reach (records-view.js), shared with the preview's test: 256
// sRGB 8-bit entries from the smallest reach (blue) to the largest (yellow).
// saturated stops, far from the lightmap view's near-grey pixels
const STOPS = [[40, 60, 255], [200, 40, 220], [255, 120, 40], [255, 230, 0]];
export const RECORD_RAMP = Array.from({ length: 256 }, (_, i) => {
  const t = (i / 255) * (STOPS.length - 1), k = Math.min(STOPS.length - 2, Math.floor(t)), f = t - k;
  return STOPS[k].map((v, c) => Math.round(v + f * (STOPS[k + 1][c] - v)));
});

