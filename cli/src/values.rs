//! Option values given as text: image sizes and vectors, parsed the same way
//! by every subcommand.

/// `--size` of every subcommand: `N` for N × N, or `WIDTHxHEIGHT`.
pub fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let parse = |v: &str| {
        v.trim().parse::<usize>().map_err(|_| {
            format!("{v:?} is not a whole number (expected N or WIDTHxHEIGHT like 512x512)")
        })
    };
    match s.split_once(['x', 'X']) {
        Some((w, h)) => Ok((parse(w)?, parse(h)?)),
        None => parse(s).map(|n| (n, n)),
    }
}

/// `--size` of the subcommands whose views are square (analytic shapes,
/// dataset presets, the demo): `N`, or `NxN`.
pub fn parse_square_size(s: &str) -> Result<usize, String> {
    match parse_size(s)? {
        (w, h) if w == h => Ok(w),
        (w, h) => Err(format!("{w}x{h}: these views are square, give N or NxN")),
    }
}

/// A whole number ≥ 0 (seeds, counts): `--seed -1` said "invalid digit
/// found in string".
pub fn parse_whole<T: std::str::FromStr>(s: &str) -> Result<T, String> {
    let t = s.trim();
    t.parse::<T>().map_err(|_| match t.parse::<i128>() {
        Ok(v) if v < 0 => format!("{s:?} is negative: a whole number ≥ 0 is expected"),
        Ok(_) => format!("{s:?} is too large"),
        Err(_) => format!("{s:?} is not a whole number"),
    })
}

/// A finite number (`--eta nan` reached the method as JSON null: "invalid
/// type: null, expected f64").
pub fn parse_finite(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("{s:?} is not a finite number")),
        Err(_) => Err(format!("{s:?} is not a number")),
    }
}

/// Parses `x,y,z` into a vector.
pub fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated numbers like 0.3,0.2,1, got {s:?}"
        ));
    }
    let mut v = [0.0f64; 3];
    for (vi, p) in v.iter_mut().zip(parts) {
        *vi = p.parse().map_err(|_| format!("{p:?} is not a number"))?;
        if !vi.is_finite() {
            return Err(format!("{p:?} is not a finite number"));
        }
    }
    Ok(v)
}

/// A frame of normals (`--axes`): one of `Axes::NAMES`.
pub fn parse_axes(name: &str) -> Result<sfp_core::prediction::Axes, String> {
    use sfp_core::prediction::Axes;
    Axes::parse(name).ok_or_else(|| format!("one of {}", Axes::NAMES.join(", ")))
}
