//! Reading PDF functions (types 0, 2, 3 and 4) of shadings and tint transforms.

use lopdf::{Dictionary, Object};

use super::bits::BitReader;
use super::colour::Function;
use super::objects::{invalid, Objects};
use super::postscript::Program;
use crate::error::Error;

/// The deepest nesting of stitching functions.
const MAX_FUNCTION_DEPTH: usize = 8;
/// The most samples of a sampled function.
const MAX_SAMPLES: u64 = 1 << 20;
/// The most bytes of a type 4 function's program.
const MAX_PROGRAM_BYTES: u64 = 1 << 20;

/// Reads a function of `inputs` inputs: of type 0, 2 or 3 (one input), an array of them, or
/// of type 4 (any number of inputs, up to 32).
pub(crate) fn read_function(
    objects: Objects,
    object: &Object,
    what: &str,
    inputs: usize,
) -> Result<Function, Error> {
    read_function_at(objects, object, what, inputs, 0)
}

fn read_function_at(
    objects: Objects,
    object: &Object,
    what: &str,
    inputs: usize,
    depth: usize,
) -> Result<Function, Error> {
    if depth > MAX_FUNCTION_DEPTH {
        return Err(invalid(what, "functions nest too deep"));
    }
    let (resolved, _) = objects.resolve(object, what)?;
    if let Object::Array(items) = resolved {
        if items.is_empty() {
            return Err(invalid(what, "an empty array of functions"));
        }
        let functions = items
            .iter()
            .enumerate()
            .map(|(k, f)| read_function_at(objects, f, &format!("{what} [{k}]"), inputs, depth + 1))
            .collect::<Result<_, _>>()?;
        return Ok(Function::Array(functions));
    }
    let dict = objects.dict(resolved, what)?;
    let domain = read_numbers(objects, dict, b"Domain", what)?
        .ok_or_else(|| invalid(what, "the function has no Domain"))?;
    if domain.len() != 2 * inputs {
        return Err(invalid(
            what,
            format!(
                "the function must have {inputs} input{} (a Domain of {} numbers); it has {}",
                if inputs == 1 { "" } else { "s" },
                2 * inputs,
                domain.len()
            ),
        ));
    }
    let kind = objects
        .get(dict, b"FunctionType", what)?
        .ok_or_else(|| invalid(what, "the function has no FunctionType"))?;
    let kind = objects.number(kind, what)?;
    if kind == 4.0 {
        return read_postscript(objects, resolved, what, &domain);
    }
    if inputs != 1 {
        return Err(invalid(
            what,
            format!("a function of {inputs} inputs of FunctionType {kind} is not read (type 4 is)"),
        ));
    }
    let domain = [domain[0], domain[1]];
    match kind {
        0.0 => read_sampled(objects, resolved, what, domain),
        2.0 => read_exponential(objects, dict, what, domain),
        3.0 => read_stitching(objects, dict, what, domain, depth),
        other => Err(invalid(
            what,
            format!("FunctionType {other} is not read (0, 2, 3 and 4 are)"),
        )),
    }
}

/// The numbers of the entry `key` of `dict`, when it has one.
fn read_numbers(
    objects: Objects,
    dict: &Dictionary,
    key: &[u8],
    what: &str,
) -> Result<Option<Vec<f64>>, Error> {
    let label = format!("{what} /{}", String::from_utf8_lossy(key));
    objects
        .get(dict, key, what)?
        .map(|o| objects.numbers(o, &label))
        .transpose()
}

/// Reads an exponential function (type 2).
fn read_exponential(
    objects: Objects,
    dict: &Dictionary,
    what: &str,
    domain: [f64; 2],
) -> Result<Function, Error> {
    let c0 = read_numbers(objects, dict, b"C0", what)?.unwrap_or_else(|| vec![0.0]);
    let c1 = read_numbers(objects, dict, b"C1", what)?.unwrap_or_else(|| vec![1.0]);
    if c0.len() != c1.len() {
        return Err(invalid(what, "C0 and C1 differ in length"));
    }
    let n = objects
        .get(dict, b"N", what)?
        .ok_or_else(|| invalid(what, "the function has no N"))?;
    let n = objects.number(n, what)?;
    Ok(Function::Exponential { domain, c0, c1, n })
}

/// Reads a stitching function (type 3) of one input.
fn read_stitching(
    objects: Objects,
    dict: &Dictionary,
    what: &str,
    domain: [f64; 2],
    depth: usize,
) -> Result<Function, Error> {
    let list = objects
        .get(dict, b"Functions", what)?
        .ok_or_else(|| invalid(what, "the stitching function has no Functions"))?;
    let functions = match objects.resolve(list, what)?.0 {
        Object::Array(items) if !items.is_empty() => items
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let label = format!("{what} /Functions [{k}]");
                read_function_at(objects, f, &label, 1, depth + 1)
            })
            .collect::<Result<Vec<_>, _>>()?,
        _ => return Err(invalid(what, "Functions must be a non-empty array")),
    };
    let bounds = read_numbers(objects, dict, b"Bounds", what)?.unwrap_or_default();
    let encode = read_numbers(objects, dict, b"Encode", what)?.unwrap_or_default();
    if bounds.len() + 1 != functions.len() || encode.len() != 2 * functions.len() {
        return Err(invalid(
            what,
            format!(
                "{} functions need {} Bounds and {} Encode numbers; found {} and {}",
                functions.len(),
                functions.len() - 1,
                2 * functions.len(),
                bounds.len(),
                encode.len()
            ),
        ));
    }
    let encode = encode.chunks(2).map(|p| [p[0], p[1]]).collect();
    Ok(Function::Stitching {
        domain,
        functions,
        bounds,
        encode,
    })
}

/// Reads a PostScript calculator function (type 4) whose `Domain` is `domain`, and runs it
/// at the corners and the centre of its domain, so that a program that fails there is an
/// error naming the object rather than a colour.
fn read_postscript(
    objects: Objects,
    object: &Object,
    what: &str,
    domain: &[f64],
) -> Result<Function, Error> {
    let stream = objects.stream(object, what)?;
    let range = read_numbers(objects, &stream.dict, b"Range", what)?
        .ok_or_else(|| invalid(what, "the type 4 function has no Range"))?;
    if range.is_empty() || range.len() % 2 != 0 || domain.len() > 64 {
        return Err(invalid(
            what,
            "Range must be pairs of numbers, and the inputs at most 32",
        ));
    }
    let source = objects.stream_data(stream, what, MAX_PROGRAM_BYTES)?;
    let program = Program::parse(&source)
        .map_err(|e| invalid(what, format!("its PostScript program cannot be read: {e}")))?;
    let pairs = |v: &[f64]| v.chunks(2).map(|p| [p[0], p[1]]).collect::<Vec<_>>();
    let function = Function::PostScript {
        domain: pairs(domain),
        range: pairs(&range),
        program,
    };
    for inputs in trial_inputs(&pairs(domain)) {
        if let Err(e) = function.try_eval(&inputs) {
            return Err(invalid(
                what,
                format!("its PostScript program fails at the inputs {inputs:?}: {e}"),
            ));
        }
    }
    Ok(function)
}

/// The inputs a type 4 function is tried at when read: the centre of its domain and its
/// corners (the first 64 of them).
fn trial_inputs(domain: &[[f64; 2]]) -> Vec<Vec<f64>> {
    let centre: Vec<f64> = domain.iter().map(|d| (d[0] + d[1]) / 2.0).collect();
    let corners = (0u64..(1u64 << domain.len().min(6))).map(|bits| {
        domain
            .iter()
            .enumerate()
            .map(|(k, d)| if (bits >> k) & 1 == 1 { d[1] } else { d[0] })
            .collect()
    });
    std::iter::once(centre).chain(corners).collect()
}

/// Reads a sampled function (type 0) of one input.
fn read_sampled(
    objects: Objects,
    object: &Object,
    what: &str,
    domain: [f64; 2],
) -> Result<Function, Error> {
    let stream = objects.stream(object, what)?;
    let dict = &stream.dict;
    let numbers = |key: &[u8]| -> Result<Option<Vec<f64>>, Error> {
        objects
            .get(dict, key, what)?
            .map(|o| objects.numbers(o, what))
            .transpose()
    };
    let size = numbers(b"Size")?.ok_or_else(|| invalid(what, "the function has no Size"))?;
    let range = numbers(b"Range")?.ok_or_else(|| invalid(what, "the function has no Range"))?;
    let bits = numbers(b"BitsPerSample")?
        .and_then(|b| b.first().copied())
        .ok_or_else(|| invalid(what, "the function has no BitsPerSample"))?;
    if size.len() != 1 || !(1.0..=MAX_SAMPLES as f64).contains(&size[0]) {
        return Err(invalid(
            what,
            format!("Size must be one count from 1 to {MAX_SAMPLES}"),
        ));
    }
    if ![1.0, 2.0, 4.0, 8.0, 12.0, 16.0, 24.0, 32.0].contains(&bits) {
        return Err(invalid(
            what,
            format!("BitsPerSample {bits} is not 1, 2, 4, 8, 12, 16, 24 or 32"),
        ));
    }
    if range.len() < 2 || range.len() % 2 != 0 {
        return Err(invalid(what, "Range must be pairs of numbers"));
    }
    let (size, bits, outputs) = (size[0] as usize, bits as u32, range.len() / 2);
    let encode = numbers(b"Encode")?.unwrap_or_else(|| vec![0.0, (size - 1) as f64]);
    let decode = numbers(b"Decode")?.unwrap_or_else(|| range.clone());
    if encode.len() != 2 || decode.len() != range.len() {
        return Err(invalid(what, "Encode or Decode has the wrong length"));
    }
    let data = objects.stream_data(stream, what, MAX_SAMPLES * 8)?;
    let needed = (size * outputs) as u64 * u64::from(bits);
    if (data.len() as u64) * 8 < needed {
        return Err(invalid(
            what,
            format!(
                "the stream holds {} bytes, fewer than its {size} samples need",
                data.len()
            ),
        ));
    }
    let mut reader = BitReader::new(&data);
    let max = ((1u64 << bits) - 1) as f64;
    let mut samples = Vec::with_capacity(size * outputs);
    for _ in 0..size {
        for k in 0..outputs {
            let raw = reader.read(bits).unwrap_or(0) as f64;
            let value = decode[2 * k] + raw * (decode[2 * k + 1] - decode[2 * k]) / max;
            samples.push(value.clamp(
                range[2 * k].min(range[2 * k + 1]),
                range[2 * k].max(range[2 * k + 1]),
            ));
        }
    }
    Ok(Function::Sampled {
        domain,
        encode: [encode[0], encode[1]],
        size,
        samples,
        outputs,
    })
}
