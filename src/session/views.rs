//! Which views the viewer has and what they are called: the ids a saved
//! session, a scene file (`maximised = "polar"`), the command line
//! (`bv render --view polar`) and the Num1–9 shortcuts refer to. The views
//! themselves (drawing code) are in the `views` folder, whose registry pairs
//! each id here with its constructor, in the same order.

/// The name of one view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ViewInfo {
    /// Stable id (saved as the maximised view, used by shortcuts).
    pub id: &'static str,
    /// Title in the view's header.
    pub title: &'static str,
    /// Whether the window's overview grid shows it. Views that need the
    /// whole window to read (the lecture's diagrams) are left out of the
    /// grid and shown maximised: from the *Views* menu, presentation mode's
    /// strip, or `bv render --view`.
    pub in_grid: bool,
}

/// The 3D polar lobe.
pub const LOBE: ViewInfo = ViewInfo {
    id: "lobe",
    title: "3D lobe",
    in_grid: true,
};

/// The sphere lit by one light.
pub const LIT_SPHERE: ViewInfo = ViewInfo {
    id: "lit_sphere",
    title: "Lit sphere",
    in_grid: true,
};

/// The plane of incidence as a polar plot.
pub const POLAR: ViewInfo = ViewInfo {
    id: "polar",
    title: "Plane of incidence (polar)",
    in_grid: true,
};

/// f against an angle.
pub const CARTESIAN: ViewInfo = ViewInfo {
    id: "cartesian",
    title: "f versus angle",
    in_grid: true,
};

/// An object under an environment map.
pub const ENVIRONMENT: ViewInfo = ViewInfo {
    id: "environment",
    title: "Environment",
    in_grid: true,
};

/// The directional albedo ρhd(θi).
pub const ALBEDO: ViewInfo = ViewInfo {
    id: "albedo",
    title: "Directional albedo ρhd(θi)",
    in_grid: true,
};

/// The Fresnel curves.
pub const FRESNEL: ViewInfo = ViewInfo {
    id: "fresnel",
    title: "Fresnel reflectance",
    in_grid: true,
};

/// The image slice in half/difference angles.
pub const SLICE: ViewInfo = ViewInfo {
    id: "slice",
    title: "Image slice (θh × θd)",
    in_grid: true,
};

/// The reciprocity map.
pub const RECIPROCITY: ViewInfo = ViewInfo {
    id: "reciprocity",
    title: "Reciprocity map",
    in_grid: false,
};

/// Snell's law at an interface.
pub const SNELL: ViewInfo = ViewInfo {
    id: "snell",
    title: "Snell's law at an interface",
    in_grid: false,
};

/// The microfacet terms D, G, F.
pub const TERMS: ViewInfo = ViewInfo {
    id: "terms",
    title: "Microfacet terms D, G, F",
    in_grid: false,
};

/// Importance sampling and its χ² test.
pub const SAMPLING: ViewInfo = ViewInfo {
    id: "sampling",
    title: "Importance sampling",
    in_grid: false,
};

/// The factorisation view (SVD against SH).
pub const FACTOR: ViewInfo = ViewInfo {
    id: "factor",
    title: "Factorisation (SVD vs SH)",
    in_grid: false,
};

/// A simulated rough surface and its virtual gonioreflectometer.
pub const MICROSURFACE: ViewInfo = ViewInfo {
    id: "microsurface",
    title: "Microsurface (simulated)",
    in_grid: false,
};

/// f(ωi, ·) over the outgoing hemisphere from above, one disc per BRDF.
pub const HEMI: ViewInfo = ViewInfo {
    id: "hemi",
    title: "Hemisphere (from above)",
    in_grid: false,
};

/// Every view, in layout order (the first two share the top row, the others
/// fill the rows below).
pub const VIEWS: &[ViewInfo] = &[
    LOBE,
    LIT_SPHERE,
    POLAR,
    CARTESIAN,
    ENVIRONMENT,
    ALBEDO,
    FRESNEL,
    SLICE,
    RECIPROCITY,
    SNELL,
    TERMS,
    SAMPLING,
    FACTOR,
    MICROSURFACE,
    HEMI,
];

/// Other names a view answers to on the command line (`bv render --view
/// lobe3d`).
pub const ALIASES: &[(&str, &str)] = &[
    ("lobe3d", LOBE.id),
    ("3d", LOBE.id),
    ("lit", LIT_SPHERE.id),
    ("sphere", LIT_SPHERE.id),
    ("lit-sphere", LIT_SPHERE.id),
    ("env", ENVIRONMENT.id),
];

/// The view with id `id`.
pub fn info(id: &str) -> Option<&'static ViewInfo> {
    VIEWS.iter().find(|v| v.id == id)
}

/// The view with id or alias `name` (case-insensitive).
pub fn find(name: &str) -> Option<&'static ViewInfo> {
    let name = name.trim().to_ascii_lowercase();
    let id = ALIASES
        .iter()
        .find(|(a, _)| *a == name)
        .map_or(name.as_str(), |(_, id)| id);
    info(id)
}

/// The ids of every view, comma-separated (for messages).
pub fn id_list() -> String {
    VIEWS.iter().map(|v| v.id).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_unique_and_aliases_resolve() {
        let mut ids: Vec<_> = VIEWS.iter().map(|v| v.id).collect();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), VIEWS.len());
        for (alias, id) in ALIASES {
            assert_eq!(find(alias).map(|v| v.id), Some(*id));
            assert!(info(alias).is_none(), "alias {alias} shadows an id");
        }
        assert_eq!(find("LOBE3D").map(|v| v.id), Some("lobe"));
        assert!(find("nope").is_none());
    }
}
