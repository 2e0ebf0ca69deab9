//! Border extrapolation, named after OpenCV's `cv::BorderTypes`: one definition for the
//! image primitives (`polar-imgproc`) and the demosaicers (`polar-sensor`).

/// How pixels outside the image are made up (OpenCV names; `|` marks the image edge,
/// for a row `abcdefgh`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Border {
    /// `gfedcb|abcdefgh|gfedcba`: OpenCV `BORDER_REFLECT_101` (= `BORDER_DEFAULT`),
    /// scipy `mode='mirror'`.
    Reflect101,
    /// `fedcba|abcdefgh|hgfedcb`: OpenCV `BORDER_REFLECT`, scipy `mode='reflect'`.
    Reflect,
    /// `aaaaaa|abcdefgh|hhhhhhh`: OpenCV `BORDER_REPLICATE`, scipy `mode='nearest'`.
    Replicate,
}

impl Border {
    /// Maps a possibly out-of-range coordinate `i` onto `0..n` (`n >= 1`), the same way
    /// OpenCV's `borderInterpolate` does, repeating the reflection for kernels wider than
    /// the image.
    pub fn index(self, i: isize, n: usize) -> usize {
        let n = n as isize;
        if (0..n).contains(&i) {
            return i as usize;
        }
        if n == 1 {
            return 0;
        }
        let mapped = match self {
            Border::Replicate => i.clamp(0, n - 1),
            Border::Reflect | Border::Reflect101 => {
                let delta = isize::from(self == Border::Reflect101);
                let mut j = i;
                while !(0..n).contains(&j) {
                    j = if j < 0 {
                        -j - 1 + delta
                    } else {
                        n - 1 - (j - n) - delta
                    };
                }
                j
            }
        };
        mapped as usize
    }

    /// Copies `row` into `out` (length `row.len() + left + right`) with `left`/`right`
    /// extrapolated pixels on each side.
    pub fn pad_row<T: Copy>(self, row: &[T], left: usize, out: &mut [T]) {
        let n = row.len();
        out[left..left + n].copy_from_slice(row);
        for (k, o) in out[..left].iter_mut().enumerate() {
            *o = row[self.index(k as isize - left as isize, n)];
        }
        for (k, o) in out[left + n..].iter_mut().enumerate() {
            *o = row[self.index((n + k) as isize, n)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_opencv_border_interpolate() {
        // Row "abcd" (n = 4), coordinates -3..7, from the OpenCV documentation pictures.
        let idx = |b: Border| (-3..7).map(|i| b.index(i, 4)).collect::<Vec<_>>();
        assert_eq!(idx(Border::Reflect101), [3, 2, 1, 0, 1, 2, 3, 2, 1, 0]);
        assert_eq!(idx(Border::Reflect), [2, 1, 0, 0, 1, 2, 3, 3, 2, 1]);
        assert_eq!(idx(Border::Replicate), [0, 0, 0, 0, 1, 2, 3, 3, 3, 3]);
    }

    #[test]
    fn kernel_wider_than_image_keeps_reflecting() {
        assert_eq!(Border::Reflect101.index(-5, 3), 1);
        assert_eq!(Border::Reflect.index(7, 3), 1);
        assert_eq!(Border::Reflect101.index(4, 1), 0);
    }
}
