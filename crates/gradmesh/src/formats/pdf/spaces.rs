//! Reading the colour spaces of shadings: device, CIE-based (`CalGray`, `CalRGB`, `Lab`,
//! `ICCBased`) and special (`Indexed`, `Separation`, `DeviceN`).

use lopdf::Object;

use super::colour::PdfColourSpace;
use super::functions::read_function;
use super::objects::{invalid, Objects};
use crate::error::Error;

/// The deepest nesting of colour spaces (an `Indexed` base, a `Separation` alternate, an
/// `ICCBased` alternate).
const MAX_SPACE_DEPTH: usize = 4;
/// The most colourants of a `DeviceN` space (the limit PDF 32000-1 gives).
const MAX_COLOURANTS: usize = 32;
/// The most bytes of an `Indexed` lookup table (256 entries of at most 32 components).
const MAX_LOOKUP_BYTES: u64 = 256 * 32;

/// Reads a colour space of a shading.
pub(crate) fn read_colour_space(
    objects: Objects,
    object: &Object,
    what: &str,
) -> Result<PdfColourSpace, Error> {
    read_space_at(objects, object, what, 0)
}

fn read_space_at(
    objects: Objects,
    object: &Object,
    what: &str,
    depth: usize,
) -> Result<PdfColourSpace, Error> {
    if depth > MAX_SPACE_DEPTH {
        return Err(invalid(
            what,
            format!("colour spaces nest deeper than {MAX_SPACE_DEPTH}"),
        ));
    }
    let (object, _) = objects.resolve(object, what)?;
    match object {
        Object::Name(n) => device_space(n).ok_or_else(|| unsupported(what, n)),
        Object::Array(items) if !items.is_empty() => {
            let family = objects.name(&items[0], what)?;
            let param = |k: usize| {
                items
                    .get(k)
                    .ok_or_else(|| invalid(what, "the colour space array is too short"))
            };
            match family {
                b"CalGray" => Ok(PdfColourSpace::Gray),
                b"CalRGB" => Ok(PdfColourSpace::Rgb),
                b"Lab" => read_lab(objects, param(1)?, what),
                b"ICCBased" => read_icc_based(objects, param(1)?, what, depth),
                b"Indexed" | b"I" => read_indexed(objects, items, what, depth),
                b"Separation" => read_tinted(objects, items, what, depth, false),
                b"DeviceN" => read_tinted(objects, items, what, depth, true),
                other => device_space(other).ok_or_else(|| unsupported(what, other)),
            }
        }
        other => Err(invalid(
            what,
            format!("expected a colour space, found {}", other.enum_variant()),
        )),
    }
}

fn device_space(name: &[u8]) -> Option<PdfColourSpace> {
    match name {
        b"DeviceGray" | b"G" => Some(PdfColourSpace::Gray),
        b"DeviceRGB" | b"RGB" => Some(PdfColourSpace::Rgb),
        b"DeviceCMYK" | b"CMYK" => Some(PdfColourSpace::Cmyk),
        _ => None,
    }
}

fn unsupported(what: &str, name: &[u8]) -> Error {
    invalid(
        what,
        format!(
            "the colour space {} is not read (DeviceGray, DeviceRGB, DeviceCMYK, CalGray, CalRGB, \
             Lab, ICCBased, Indexed, Separation and DeviceN are)",
            String::from_utf8_lossy(name)
        ),
    )
}

/// `[/Lab << /WhitePoint [...] /Range [...] >>]`.
fn read_lab(objects: Objects, dict: &Object, what: &str) -> Result<PdfColourSpace, Error> {
    let dict = objects.dict(dict, what)?;
    let white = objects
        .get(dict, b"WhitePoint", what)?
        .ok_or_else(|| invalid(what, "the Lab space has no WhitePoint"))?;
    let white = objects.numbers(white, &format!("{what} /WhitePoint"))?;
    if white.len() != 3 || white.iter().any(|&w| w <= 0.0) {
        return Err(invalid(what, "WhitePoint must be 3 positive numbers"));
    }
    Ok(PdfColourSpace::Lab {
        white: [white[0], white[1], white[2]],
    })
}

/// The ranges of the components of the Lab space `object` (`L` from 0 to 100, `a` and `b`
/// from its `Range`, -100 to 100 when it has none).
fn lab_ranges(objects: Objects, object: &Object, what: &str) -> Result<Vec<[f64; 2]>, Error> {
    let mut ranges = vec![[0.0, 100.0], [-100.0, 100.0], [-100.0, 100.0]];
    if let Object::Array(items) = objects.resolve(object, what)?.0 {
        if let Some(dict) = items.get(1) {
            let dict = objects.dict(dict, what)?;
            if let Some(range) = objects.get(dict, b"Range", what)? {
                let r = objects.numbers(range, &format!("{what} /Range"))?;
                if r.len() != 4 {
                    return Err(invalid(format!("{what} /Range"), "expected 4 numbers"));
                }
                ranges[1] = [r[0], r[1]];
                ranges[2] = [r[2], r[3]];
            }
        }
    }
    Ok(ranges)
}

/// `[/ICCBased stream]`: its `Alternate`, else the device space of its `N`.
fn read_icc_based(
    objects: Objects,
    stream: &Object,
    what: &str,
    depth: usize,
) -> Result<PdfColourSpace, Error> {
    let dict = objects.dict(stream, what)?;
    if let Some(alternate) = objects.get(dict, b"Alternate", what)? {
        return read_space_at(objects, alternate, &format!("{what} /Alternate"), depth + 1);
    }
    let n = objects
        .get(dict, b"N", what)?
        .ok_or_else(|| invalid(what, "the ICC profile stream has no N"))?;
    match objects.number(n, &format!("{what} /N"))? {
        1.0 => Ok(PdfColourSpace::Gray),
        3.0 => Ok(PdfColourSpace::Rgb),
        4.0 => Ok(PdfColourSpace::Cmyk),
        other => Err(invalid(
            what,
            format!("an ICC profile of {other} components"),
        )),
    }
}

/// `[/Indexed base hival lookup]`: the lookup table (a string or a stream) decoded into
/// components of the base space.
fn read_indexed(
    objects: Objects,
    items: &[Object],
    what: &str,
    depth: usize,
) -> Result<PdfColourSpace, Error> {
    if items.len() != 4 {
        return Err(invalid(
            what,
            format!(
                "an Indexed space has 4 entries; this one has {}",
                items.len()
            ),
        ));
    }
    let base_what = format!("{what} (the Indexed base)");
    let base = read_space_at(objects, &items[1], &base_what, depth + 1)?;
    if matches!(base, PdfColourSpace::Indexed { .. }) {
        return Err(invalid(what, "the base of an Indexed space is Indexed"));
    }
    let hival = objects.number(&items[2], &format!("{what} (hival)"))?;
    if hival.fract() != 0.0 || !(0.0..=255.0).contains(&hival) {
        return Err(invalid(
            what,
            format!("hival {hival} is not an integer from 0 to 255"),
        ));
    }
    let entries = hival as usize + 1;
    let bytes = lookup_bytes(objects, &items[3], what)?;
    let m = base.components();
    if bytes.len() < entries * m {
        return Err(invalid(
            what,
            format!(
                "the lookup table holds {} bytes; {entries} colours of {m} components need {}",
                bytes.len(),
                entries * m
            ),
        ));
    }
    let ranges = match base {
        PdfColourSpace::Lab { .. } => lab_ranges(objects, &items[1], &base_what)?,
        _ => vec![[0.0, 1.0]; m],
    };
    let lookup = bytes[..entries * m]
        .chunks(m)
        .flat_map(|colour| {
            colour
                .iter()
                .zip(&ranges)
                .map(|(&b, r)| r[0] + f64::from(b) * (r[1] - r[0]) / 255.0)
        })
        .collect();
    Ok(PdfColourSpace::Indexed {
        base: Box::new(base),
        lookup,
    })
}

/// The bytes of an `Indexed` space's lookup table: a string or a stream.
fn lookup_bytes(objects: Objects, object: &Object, what: &str) -> Result<Vec<u8>, Error> {
    let label = format!("{what} (the lookup table)");
    match objects.resolve(object, &label)?.0 {
        Object::String(bytes, _) => Ok(bytes.clone()),
        Object::Stream(stream) => objects.stream_data(stream, &label, MAX_LOOKUP_BYTES),
        other => Err(invalid(
            label,
            format!(
                "expected a string or a stream, found {}",
                other.enum_variant()
            ),
        )),
    }
}

/// `[/Separation name alternate tint]` (`device_n` false) or `[/DeviceN names alternate tint
/// attributes?]`: colourants taken through the tint transform into the alternate space.
fn read_tinted(
    objects: Objects,
    items: &[Object],
    what: &str,
    depth: usize,
    device_n: bool,
) -> Result<PdfColourSpace, Error> {
    let family = if device_n { "DeviceN" } else { "Separation" };
    if items.len() < 4 || (!device_n && items.len() != 4) || items.len() > 5 {
        return Err(invalid(
            what,
            format!("a {family} space of {} entries", items.len()),
        ));
    }
    let colourants = if device_n {
        match objects.resolve(&items[1], what)?.0 {
            Object::Array(names) if (1..=MAX_COLOURANTS).contains(&names.len()) => names.len(),
            _ => {
                return Err(invalid(
                    what,
                    format!("a DeviceN space names 1 to {MAX_COLOURANTS} colourants in an array"),
                ))
            }
        }
    } else {
        objects.name(&items[1], what)?;
        1
    };
    let alternate = read_space_at(
        objects,
        &items[2],
        &format!("{what} (the {family} alternate)"),
        depth + 1,
    )?;
    let tint = read_function(
        objects,
        &items[3],
        &format!("{what} (the {family} tint transform)"),
        colourants,
    )?;
    Ok(PdfColourSpace::Tinted {
        colourants,
        alternate: Box::new(alternate),
        tint: Box::new(tint),
    })
}
