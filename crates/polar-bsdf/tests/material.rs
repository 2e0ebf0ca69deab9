//! Scene-file materials: parsing (TOML), validation messages, labels, presets
//! and textures.

use polar_bsdf::{Bsdf, Error, Material, Metal, Texture};

fn parse(text: &str) -> Material {
    toml::from_str(text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

fn invalid_field(text: &str) -> &'static str {
    match parse(text).validate() {
        Err(Error::InvalidParameter { field, .. }) => field,
        Ok(()) => panic!("{text} validated"),
    }
}

#[test]
fn every_material_parses_validates_and_builds() {
    let cases = [
        ("type = 'lambertian'\nalbedo = 0.5", true),
        (
            "type = 'lambertian'\nalbedo = { checkerboard = [0.2, 0.8], scale = 4.0 }",
            true,
        ),
        ("type = 'conductor'\nmetal = 'au'", true),
        (
            "type = 'conductor'\nmetal = 'Cu'\nroughness = [0.05, 0.3]",
            true,
        ),
        (
            "type = 'conductor'\nn = 0.2\nk = 3.0\nroughness = 0.1",
            true,
        ),
        ("type = 'dielectric'\nior = 1.5", false),
        (
            "type = 'dielectric'\nior = 1.33\next_ior = 1.0\nroughness = 0.2",
            false,
        ),
        ("type = 'plastic'", true),
        (
            "type = 'plastic'\nalbedo = 0.3\nior = 1.5\nroughness = 0.0",
            true,
        ),
        ("type = 'polarizer'\nangle_deg = 30.0", false),
        (
            "type = 'retarder'\nangle_deg = 45.0\nretardance_deg = 90.0",
            false,
        ),
    ];
    // The second item: opaque (two-sided) or transmissive (one-sided).
    for (text, two_sided) in cases {
        let m = parse(text);
        m.validate().unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!(m.bsdf([0.5, 0.5]).is_two_sided(), two_sided, "{text}");
        assert_eq!(m.uses_uv(), text.contains("checkerboard"), "{text}");
        let wo = nalgebra::Vector3::new(0.3, 0.1, 0.9).normalize();
        let s = m.bsdf([0.3, 0.7]).sample(&wo, [0.4, 0.6, 0.2]);
        assert!(
            s.is_some_and(|s| s.weight.iter().all(|v| v.is_finite())),
            "{text}"
        );
    }
}

#[test]
fn bad_values_name_their_field() {
    assert_eq!(
        invalid_field("type = 'conductor'\nmetal = 'au'\nroughness = -0.1"),
        "roughness"
    );
    assert_eq!(
        invalid_field("type = 'conductor'\nmetal = 'au'\nroughness = [0.1, nan]"),
        "roughness"
    );
    assert_eq!(invalid_field("type = 'conductor'\nn = 0.2\nk = -1.0"), "k");
    assert_eq!(invalid_field("type = 'conductor'\nn = 0.0"), "n");
    assert_eq!(invalid_field("type = 'conductor'\nk = 1.0"), "n");
    assert_eq!(
        invalid_field("type = 'conductor'\nmetal = 'ag'\nn = 1.0"),
        "metal"
    );
    assert_eq!(invalid_field("type = 'dielectric'\nior = 0.0"), "ior");
    assert_eq!(invalid_field("type = 'dielectric'\nior = nan"), "ior");
    assert_eq!(
        invalid_field("type = 'dielectric'\nior = 1.5\next_ior = -1.0"),
        "ext_ior"
    );
    assert_eq!(invalid_field("type = 'dielectric'\nior = inf"), "ior");
    assert_eq!(invalid_field("type = 'lambertian'\nalbedo = 1.5"), "albedo");
    assert_eq!(
        invalid_field("type = 'plastic'\nalbedo = { checkerboard = [0.2, -0.1] }"),
        "albedo"
    );
    assert_eq!(
        invalid_field("type = 'plastic'\nalbedo = { checkerboard = [0.2, 0.1], scale = 0.0 }"),
        "scale"
    );
    assert_eq!(
        invalid_field("type = 'retarder'\nretardance_deg = nan"),
        "retardance_deg"
    );
    let message = parse("type = 'dielectric'\nior = -2.0")
        .validate()
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("ior") && message.contains("> 0") && message.contains("-2"),
        "{message}"
    );
}

#[test]
fn unknown_keys_and_names_are_rejected() {
    for text in [
        "type = 'dielectric'\nior = 1.5\nroughnes = 0.1",
        "type = 'conductor'\nmetal = 'unobtainium'",
        "type = 'velvet'",
        "type = 'lambertian'\nalbedo = { checkerboard = [0.2, 0.8], scael = 2.0 }",
    ] {
        assert!(
            toml::from_str::<Material>(text).is_err(),
            "accepted: {text}"
        );
    }
}

#[test]
fn metal_presets_have_the_reflectance_of_their_colour() {
    // Normal-incidence reflectance R = ((n−1)² + k²) / ((n+1)² + k²) near 550 nm:
    // silver and aluminium are bright, gold and copper absorb green.
    let r = |m: Metal| {
        let c = m.ior();
        ((c.re - 1.0).powi(2) + c.im.powi(2)) / ((c.re + 1.0).powi(2) + c.im.powi(2))
    };
    assert!(
        r(Metal::Ag) > 0.95 && r(Metal::Al) > 0.9,
        "{} {}",
        r(Metal::Ag),
        r(Metal::Al)
    );
    assert!(
        r(Metal::Au) < 0.85 && r(Metal::Cu) < 0.7,
        "{} {}",
        r(Metal::Au),
        r(Metal::Cu)
    );
}

#[test]
fn checkerboard_alternates_and_drives_the_bsdf() {
    let m = parse("type = 'plastic'\nalbedo = { checkerboard = [0.2, 0.8] }");
    let Material::Plastic(p) = &m else {
        unreachable!()
    };
    assert_eq!(p.albedo.eval([0.1, 0.1]), 0.2);
    assert_eq!(p.albedo.eval([0.6, 0.1]), 0.8);
    assert_eq!(p.albedo.eval([0.6, 0.6]), 0.2);
    assert_eq!(p.albedo.eval([-0.1, 0.1]), 0.8);
    assert_eq!(p.albedo.mean(), 0.5);
    let albedo_at = |uv| match m.bsdf(uv) {
        Bsdf::Plastic(b) => (b.albedo, b.specular_prob),
        other => panic!("{other:?}"),
    };
    // Mitsuba's lobe choice: specular with probability 1 / (1 + mean albedo).
    assert_eq!(albedo_at([0.1, 0.1]), (0.2, 1.0 / 1.5));
    assert_eq!(albedo_at([0.9, 0.1]), (0.8, 1.0 / 1.5));
    assert_eq!(Texture::Constant(0.3).mean(), 0.3);
}
