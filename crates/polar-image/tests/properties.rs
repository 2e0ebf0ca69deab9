//! Property tests of the foundation types: buffers, pixel indexing, channel split and
//! join, and the border rule every filter and demosaicer relies on.

use polar_image::{Border, Gray, Image, ImageError, is_mosaic_size};
use proptest::prelude::*;

fn image3() -> impl Strategy<Value = Image<i32, 3>> {
    (1usize..9, 1usize..9).prop_flat_map(|(w, h)| {
        proptest::collection::vec(-1000i32..1000, w * h * 3)
            .prop_map(move |v| Image::from_vec(w, h, v).unwrap())
    })
}

proptest! {
    #[test]
    fn buffer_length_must_be_width_times_height_times_channels(w in 0usize..20, h in 0usize..20, extra in 1usize..5) {
        prop_assert!(Image::<u8, 2>::from_vec(w, h, vec![0; w * h * 2]).is_ok());
        let bad = Image::<u8, 2>::from_vec(w, h, vec![0; w * h * 2 + extra]);
        let is_buffer_size_error = matches!(bad, Err(ImageError::BufferSize { .. }));
        prop_assert!(is_buffer_size_error);
    }

    #[test]
    fn pixel_x_y_is_row_major(img in image3()) {
        let (w, h) = img.size();
        for y in 0..h {
            for x in 0..w {
                let k = (y * w + x) * 3;
                prop_assert_eq!(img.pixel(x, y), &[img.as_slice()[k], img.as_slice()[k + 1], img.as_slice()[k + 2]]);
            }
        }
    }

    #[test]
    fn channels_split_and_join_to_the_same_image(img in image3()) {
        let (a, b, c) = (img.channel(0), img.channel(1), img.channel(2));
        prop_assert_eq!(Image::from_channels([&a, &b, &c]).unwrap(), img.clone());
        prop_assert_eq!(img.clone().into_vec().len(), img.width() * img.height() * 3);
    }

    #[test]
    fn channels_of_different_sizes_do_not_join(w in 1usize..6, h in 1usize..6) {
        let a: Gray<u8> = Gray::new(w, h);
        let b: Gray<u8> = Gray::new(w + 1, h);
        prop_assert!(Image::<u8, 2>::from_channels([&a, &b]).is_err());
    }

    #[test]
    fn border_index_stays_inside_and_is_identity_inside(i in -50isize..50, n in 1usize..12) {
        for b in [Border::Reflect101, Border::Reflect, Border::Replicate] {
            let j = b.index(i, n);
            prop_assert!(j < n);
            if (0..n as isize).contains(&i) {
                prop_assert_eq!(j as isize, i);
            }
        }
    }

    #[test]
    fn reflect_101_keeps_the_parity_of_the_offset(i in -50isize..50, half in 1usize..8) {
        // On an even-sized mosaic row, reflect-101 keeps every sample's polarizer (parity).
        let n = 2 * half;
        prop_assert_eq!(Border::Reflect101.index(i, n) % 2, i.rem_euclid(2) as usize);
    }

    #[test]
    fn mosaic_size_is_whole_super_pixels(w in 0usize..40, h in 0usize..40) {
        prop_assert_eq!(is_mosaic_size(w, h), w >= 2 && h >= 2 && w % 2 == 0 && h % 2 == 0);
    }
}
