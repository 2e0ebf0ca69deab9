//! Exact Euclidean distance transform of a mask (Felzenszwalb & Huttenlocher, "Distance
//! transforms of sampled functions", Theory of Computing 2012: two passes of the 1-D
//! squared transform), matching `cv2.distanceTransform(src, DIST_L2, DIST_MASK_PRECISE)`.

use rayon::prelude::*;

/// What the pixels outside the image count as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outside {
    /// Background: a mask pixel on the border is one pixel from it (a region cut by the
    /// frame ends there).
    Background,
    /// Not background: distances are to background pixels inside the image only (a border
    /// cut is no outline).
    NotBackground,
}

/// Euclidean distance (pixels) from each pixel of the `w x h` mask `fg` to the nearest
/// pixel off it, `outside` saying what lies beyond the image; 0 off the mask, infinite
/// everywhere when no pixel is background.
pub fn distance_to_background(fg: &[bool], w: usize, h: usize, outside: Outside) -> Vec<f64> {
    if outside == Outside::Background {
        let (pw, ph) = (w + 2, h + 2);
        let padded: Vec<bool> = (0..pw * ph)
            .map(|k| {
                let (x, y) = (k % pw, k / pw);
                (1..=w).contains(&x) && (1..=h).contains(&y) && fg[(y - 1) * w + x - 1]
            })
            .collect();
        let d = distance_to_background(&padded, pw, ph, Outside::NotBackground);
        return (0..w * h)
            .map(|k| d[(k / w + 1) * pw + k % w + 1])
            .collect();
    }
    if fg.iter().all(|&f| f) {
        return vec![f64::INFINITY; w * h];
    }
    let inf_or_zero = |f: bool| if f { f64::INFINITY } else { 0.0 };
    // Columns into a column-major buffer, then rows back into row-major order.
    let mut cols = vec![0.0f64; w * h];
    cols.par_chunks_mut(h)
        .enumerate()
        .for_each_init(Edt::default, |edt, (x, out)| {
            edt.run((0..h).map(|y| inf_or_zero(fg[y * w + x])), out);
        });
    let mut d = vec![0.0f64; w * h];
    d.par_chunks_mut(w)
        .enumerate()
        .for_each_init(Edt::default, |edt, (y, out)| {
            edt.run((0..w).map(|x| cols[x * h + y]), out);
            out.iter_mut().for_each(|v| *v = v.sqrt());
        });
    d
}

/// Scratch of [`edt_1d`], reused across the lines of one thread.
#[derive(Default)]
struct Edt {
    f: Vec<f64>,
    v: Vec<usize>,
    z: Vec<f64>,
}

impl Edt {
    /// The squared distance transform of the line `f` into `out`.
    fn run(&mut self, f: impl Iterator<Item = f64>, out: &mut [f64]) {
        self.f.clear();
        self.f.extend(f);
        edt_1d(&self.f, out, &mut self.v, &mut self.z);
    }
}

/// 1-D squared distance transform of `f` (lower envelope of parabolas) into `out`.
fn edt_1d(f: &[f64], out: &mut [f64], v: &mut Vec<usize>, z: &mut Vec<f64>) {
    let n = f.len();
    out.fill(f64::INFINITY);
    v.clear();
    v.resize(n, 0);
    z.clear();
    z.resize(n + 1, 0.0);
    let mut k = 0usize;
    let mut started = false;
    for q in 0..n {
        if f[q].is_infinite() {
            continue;
        }
        if !started {
            v[0] = q;
            z[0] = f64::NEG_INFINITY;
            z[1] = f64::INFINITY;
            started = true;
            continue;
        }
        loop {
            let p = v[k];
            let s =
                ((f[q] + (q * q) as f64) - (f[p] + (p * p) as f64)) / (2.0 * (q as f64 - p as f64));
            if s <= z[k] && k > 0 {
                k -= 1;
                continue;
            }
            if s <= z[k] {
                // k == 0 and the new parabola dominates everywhere.
                v[0] = q;
                z[0] = f64::NEG_INFINITY;
                z[1] = f64::INFINITY;
                break;
            }
            k += 1;
            v[k] = q;
            z[k] = s;
            z[k + 1] = f64::INFINITY;
            break;
        }
    }
    if !started {
        return;
    }
    k = 0;
    for (q, o) in out.iter_mut().enumerate() {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let p = v[k];
        let dq = q as f64 - p as f64;
        *o = dq * dq + f[p];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three background pixels in a 9x7 mask: the distances equal the nearest of the three
    /// (exact), or of them and the frame.
    #[test]
    fn distances_match_brute_force() {
        let (w, h) = (9, 7);
        let holes = [(0.0, 0.0), (6.0, 4.0), (3.0, 6.0)];
        let fg: Vec<bool> = (0..w * h)
            .map(|k| !holes.contains(&((k % w) as f64, (k / w) as f64)))
            .collect();
        for outside in [Outside::NotBackground, Outside::Background] {
            let d = distance_to_background(&fg, w, h, outside);
            for (k, dk) in d.iter().enumerate() {
                let (x, y) = ((k % w) as f64, (k / w) as f64);
                let frame = (x + 1.0).min(y + 1.0).min(w as f64 - x).min(h as f64 - y);
                let brute = holes
                    .iter()
                    .map(|(a, b)| (x - a).hypot(y - b))
                    .fold(f64::INFINITY, f64::min);
                let want = match outside {
                    Outside::NotBackground => brute,
                    Outside::Background => brute.min(frame),
                };
                assert!((dk - want).abs() < 1e-12, "{outside:?} {k}: {dk} {want}");
            }
        }
        let all = distance_to_background(&[true; 4], 2, 2, Outside::NotBackground);
        assert!(all.iter().all(|v| v.is_infinite()));
        let framed = distance_to_background(&[true; 4], 2, 2, Outside::Background);
        assert!(framed.iter().all(|&v| v == 1.0), "{framed:?}");
    }
}
