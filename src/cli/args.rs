//! Value parsers shared by the subcommands' arguments (sizes, seconds, exposures), each with the
//! allowed range in its error.

pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    use crate::scene::stage::{MAX_PIXELS, MAX_SIDE};
    let err = || {
        format!(
            "`{s}`: expected WxH with each side in 1..={MAX_SIDE} and at most {MAX_PIXELS} pixels \
             (8192x8192), e.g. 480x360"
        )
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(err)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| err())?,
        h.trim().parse().map_err(|_| err())?,
    );
    if !(1..=MAX_SIDE).contains(&w)
        || !(1..=MAX_SIDE).contains(&h)
        || u64::from(w) * u64::from(h) > MAX_PIXELS
    {
        return Err(err());
    }
    Ok((w, h))
}

pub(crate) fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 1e7 => Ok(v),
        _ => Err(format!("`{s}`: expected seconds in (0, 1e7]")),
    }
}

pub(crate) fn parse_exposure(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if (-30.0..=30.0).contains(&v) => Ok(v),
        _ => Err(format!("`{s}`: expected stops in -30..=30")),
    }
}
