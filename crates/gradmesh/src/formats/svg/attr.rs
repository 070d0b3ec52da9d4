//! Attributes and style properties of SVG elements, parsed with `svgtypes`, and errors that
//! name the element.

use std::str::FromStr;

use kurbo::Affine;
use roxmltree::Node;

use crate::error::{Error, ErrorKind, Location, Warning, WarningKind};

/// The SVG namespace.
pub(super) const SVG_NS: &str = "http://www.w3.org/2000/svg";
/// The XLink namespace (`xlink:href`).
pub(super) const XLINK_NS: &str = "http://www.w3.org/1999/xlink";

/// The element's name in messages: `<stop id="s1">`, or `<stop>` without an id.
pub(super) fn describe(node: Node) -> String {
    let tag = node.tag_name().name();
    match node.attribute("id") {
        Some(id) => format!("<{tag} id=\"{id}\">"),
        None => format!("<{tag}>"),
    }
}

/// The line and column (1-based) where the element starts.
pub(super) fn line_column(node: Node) -> (usize, usize) {
    super::lines::line_column(node.document(), node.range().start)
}

/// An error about `node`: located at its line, the message naming the element and its column.
pub(super) fn error_at(node: Node, message: impl std::fmt::Display) -> Error {
    let (line, column) = line_column(node);
    Error {
        location: Location::default().at_line(line),
        kind: ErrorKind::Syntax(format!("{} at column {column}: {message}", describe(node))),
    }
}

/// A limit error about `node`.
pub(super) fn limit_at(node: Node, what: String, found: u64, limit: u64) -> Error {
    let (line, _) = line_column(node);
    Error {
        location: Location::default().at_line(line),
        kind: ErrorKind::LimitExceeded { what, found, limit },
    }
}

/// A warning of `kind` about `node`, naming it and its line.
pub(super) fn warning_at(
    node: Node,
    kind: WarningKind,
    message: impl std::fmt::Display,
) -> Warning {
    let (line, column) = line_column(node);
    Warning::new(
        kind,
        format!("{} at {line}:{column}: {message}", describe(node)),
    )
}

/// A warning that an invalid attribute of `node` is ignored, from the error reading it gave
/// (which names the element, the attribute and the value).
pub(super) fn ignored(node: Node, e: &Error) -> Warning {
    let text = e.kind.to_string();
    let (_, column) = line_column(node);
    let prefix = format!("{} at column {column}: ", describe(node));
    let message = text.strip_prefix(&prefix).unwrap_or(&text);
    warning_at(
        node,
        WarningKind::SvgReadDifferently,
        format!("{message}: ignored"),
    )
}

/// Whether `node` is an SVG element (or an element in no namespace) named one of `names`.
pub(super) fn is_svg_element(node: Node, names: &[&str]) -> bool {
    let tag = node.tag_name();
    node.is_element()
        && matches!(tag.namespace(), None | Some(SVG_NS))
        && names.contains(&tag.name())
}

/// The value of property `name` set on `node` itself: from its `style` attribute (the last
/// declaration wins, as in CSS), else from the presentation attribute of that name.
pub(super) fn own_property<'a>(node: Node<'a, '_>, name: &str) -> Option<&'a str> {
    let from_style = node.attribute("style").and_then(|style| {
        style
            .split(';')
            .filter_map(|declaration| declaration.split_once(':'))
            .filter(|(key, _)| key.trim() == name)
            .map(|(_, value)| value.trim().trim_end_matches("!important").trim_end())
            .next_back()
    });
    from_style.or_else(|| node.attribute(name).map(str::trim))
}

/// The value of an inherited property at `node`: its own, else its nearest ancestor's.
pub(super) fn inherited_property<'a>(node: Node<'a, '_>, name: &str) -> Option<&'a str> {
    node.ancestors()
        .filter(Node::is_element)
        .filter_map(|n| own_property(n, name))
        .find(|v| *v != "inherit")
}

/// A finite number.
pub(super) fn number(node: Node, what: &str, text: &str) -> Result<f64, Error> {
    let value = svgtypes::Number::from_str(text.trim())
        .map_err(|e| error_at(node, format!("{what} {text:?} is not a number ({e})")))?
        .0;
    finite(node, what, value)
}

/// Refuses NaN and infinities (svgtypes reads `1e999` as infinity).
pub(super) fn finite(node: Node, what: &str, value: f64) -> Result<f64, Error> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(error_at(node, format!("{what} is not a finite number")))
    }
}

/// A length in user units (CSS pixels); a percentage is of `percent_base`.
pub(super) fn length(node: Node, what: &str, text: &str, percent_base: f64) -> Result<f64, Error> {
    use svgtypes::LengthUnit as U;
    let length = svgtypes::Length::from_str(text.trim())
        .map_err(|e| error_at(node, format!("{what} {text:?} is not a length ({e})")))?;
    let scale = match length.unit {
        U::None | U::Px => 1.0,
        U::In => 96.0,
        U::Cm => 96.0 / 2.54,
        U::Mm => 96.0 / 25.4,
        U::Pt => 4.0 / 3.0,
        U::Pc => 16.0,
        // The initial font size, 16px; ex is taken as half an em.
        U::Em => 16.0,
        U::Ex => 8.0,
        U::Percent => percent_base / 100.0,
    };
    finite(node, what, length.number * scale)
}

/// The length attribute `name` of `node`, or `default` when absent.
pub(super) fn length_attribute(
    node: Node,
    name: &str,
    percent_base: f64,
    default: f64,
) -> Result<f64, Error> {
    match node.attribute(name) {
        Some(text) => length(node, name, text, percent_base),
        None => Ok(default),
    }
}

/// The transform list in attribute `name` of `node` (identity when absent).
pub(super) fn transform_attribute(node: Node, name: &str) -> Result<Affine, Error> {
    let Some(text) = node.attribute(name) else {
        return Ok(Affine::IDENTITY);
    };
    let t = svgtypes::Transform::from_str(text).map_err(|e| {
        error_at(
            node,
            format!("{name} {text:?} is not a transform list ({e})"),
        )
    })?;
    let coefficients = [t.a, t.b, t.c, t.d, t.e, t.f];
    if coefficients.iter().all(|v| v.is_finite()) {
        Ok(Affine::new(coefficients))
    } else {
        Err(error_at(node, format!("{name} {text:?} is not finite")))
    }
}

/// An opacity value (a number or a percentage), clamped to 0..1 as CSS does.
pub(super) fn opacity(node: Node, what: &str, text: &str) -> Result<f64, Error> {
    let text = text.trim();
    let value = match text.strip_suffix('%') {
        Some(percent) => number(node, what, percent)? / 100.0,
        None => number(node, what, text)?,
    };
    Ok(value.clamp(0.0, 1.0))
}

/// The product of an opacity property on `node` itself (1 when absent).
pub(super) fn own_opacity(node: Node, name: &str) -> Result<f64, Error> {
    match own_property(node, name) {
        Some(text) if text != "inherit" => opacity(node, name, text),
        _ => Ok(1.0),
    }
}

/// A colour as sRGB in 0..1 and its alpha. `currentColor` is the inherited `color`.
pub(super) fn colour(node: Node, what: &str, text: &str) -> Result<([f64; 3], f64), Error> {
    let text = if text == "currentColor" {
        inherited_property(node, "color").unwrap_or("black")
    } else {
        text
    };
    let c = svgtypes::Color::from_str(text)
        .map_err(|e| error_at(node, format!("{what} {text:?} is not a colour ({e})")))?;
    let unit = |v: u8| f64::from(v) / 255.0;
    Ok(([unit(c.red), unit(c.green), unit(c.blue)], unit(c.alpha)))
}

/// The target of a local reference `#id`; an external reference is refused, never fetched.
pub(super) fn local_reference<'a>(node: Node, what: &str, text: &'a str) -> Result<&'a str, Error> {
    match text.trim().strip_prefix('#') {
        Some(id) if !id.is_empty() => Ok(id),
        _ => Err(error_at(
            node,
            format!("{what} {text:?} is not a reference into this file (#id); other files are never read"),
        )),
    }
}

/// The `href` of `node`: plain (SVG 2) or `xlink:href`.
pub(super) fn href<'a>(node: Node<'a, '_>) -> Option<&'a str> {
    node.attribute((XLINK_NS, "href"))
        .or_else(|| node.attribute("href"))
}
