//! Type 4 functions: PDF's PostScript calculator (PDF 32000-1, 7.10.5), parsed into a tree of
//! operations and run on a bounded stack.

/// The deepest the operand stack may grow (the limit PDF 32000-1 gives for type 4 functions).
pub const MAX_STACK: usize = 100;
/// The most operations one evaluation may run; a program without loops runs each of its
/// operations at most once, so this also bounds a program's length.
pub const MAX_OPERATIONS: usize = 100_000;
/// The deepest nesting of `{ }` blocks.
const MAX_NESTING: usize = 64;

/// A value on the stack.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Value {
    Int(i64),
    Real(f64),
    Bool(bool),
}

/// An operator of the calculator.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Operator {
    Abs,
    Add,
    Atan,
    Ceiling,
    Cos,
    Cvi,
    Cvr,
    Div,
    Exp,
    Floor,
    Idiv,
    Ln,
    Log,
    Mod,
    Mul,
    Neg,
    Round,
    Sin,
    Sqrt,
    Sub,
    Truncate,
    And,
    Bitshift,
    Eq,
    Ge,
    Gt,
    Le,
    Lt,
    Ne,
    Not,
    Or,
    Xor,
    Copy,
    Dup,
    Exch,
    Index,
    Pop,
    Roll,
}

impl Operator {
    fn from_name(name: &str) -> Option<Operator> {
        use Operator::*;
        Some(match name {
            "abs" => Abs,
            "add" => Add,
            "atan" => Atan,
            "ceiling" => Ceiling,
            "cos" => Cos,
            "cvi" => Cvi,
            "cvr" => Cvr,
            "div" => Div,
            "exp" => Exp,
            "floor" => Floor,
            "idiv" => Idiv,
            "ln" => Ln,
            "log" => Log,
            "mod" => Mod,
            "mul" => Mul,
            "neg" => Neg,
            "round" => Round,
            "sin" => Sin,
            "sqrt" => Sqrt,
            "sub" => Sub,
            "truncate" => Truncate,
            "and" => And,
            "bitshift" => Bitshift,
            "eq" => Eq,
            "ge" => Ge,
            "gt" => Gt,
            "le" => Le,
            "lt" => Lt,
            "ne" => Ne,
            "not" => Not,
            "or" => Or,
            "xor" => Xor,
            "copy" => Copy,
            "dup" => Dup,
            "exch" => Exch,
            "index" => Index,
            "pop" => Pop,
            "roll" => Roll,
            _ => return None,
        })
    }
}

/// One step of a program.
#[derive(Clone, Debug, PartialEq)]
enum Step {
    Push(Value),
    Apply(Operator),
    If(Vec<Step>),
    IfElse(Vec<Step>, Vec<Step>),
}

/// A parsed calculator program.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    steps: Vec<Step>,
}

/// What a parse meets while reading a block: a step, or a block waiting for `if`/`ifelse`.
enum Item {
    Step(Step),
    Block(Vec<Step>),
}

impl Program {
    /// Parses the program text `source`: one `{ }` block of numbers, `true`, `false`,
    /// operators and nested blocks before `if` or `ifelse`.
    pub fn parse(source: &[u8]) -> Result<Program, String> {
        let mut tokens = Tokens {
            source,
            at: 0,
            count: 0,
        };
        match tokens.next_token()? {
            Some(b"{") => {}
            Some(other) => {
                return Err(format!(
                    "the program must start with {{, not {}",
                    String::from_utf8_lossy(other)
                ))
            }
            None => return Err("the program is empty".into()),
        }
        let steps = parse_block(&mut tokens, 1)?;
        if let Some(extra) = tokens.next_token()? {
            return Err(format!(
                "{} after the program's closing }}",
                String::from_utf8_lossy(extra)
            ));
        }
        Ok(Program { steps })
    }

    /// Runs the program on `inputs` and returns the top `outputs` values of the stack, bottom
    /// first.
    pub fn run(&self, inputs: &[f64], outputs: usize) -> Result<Vec<f64>, String> {
        let mut machine = Machine {
            stack: Vec::with_capacity(MAX_STACK),
            operations: 0,
        };
        for &x in inputs {
            machine.push(Value::Real(x))?;
        }
        machine.run(&self.steps)?;
        if machine.stack.len() < outputs {
            return Err(format!(
                "the program leaves {} value{} on the stack; {outputs} are needed",
                machine.stack.len(),
                if machine.stack.len() == 1 { "" } else { "s" }
            ));
        }
        let top = &machine.stack[machine.stack.len() - outputs..];
        top.iter().map(|&v| number(v)).collect()
    }
}

/// The tokens of a program: `{`, `}`, and words (numbers and names) between white space.
struct Tokens<'a> {
    source: &'a [u8],
    at: usize,
    count: usize,
}

impl<'a> Tokens<'a> {
    fn next_token(&mut self) -> Result<Option<&'a [u8]>, String> {
        let s = self.source;
        while self.at < s.len() {
            match s[self.at] {
                b'%' => {
                    while self.at < s.len() && s[self.at] != b'\n' && s[self.at] != b'\r' {
                        self.at += 1;
                    }
                }
                c if c.is_ascii_whitespace() || c == 0 => self.at += 1,
                _ => break,
            }
        }
        if self.at >= s.len() {
            return Ok(None);
        }
        self.count += 1;
        if self.count > MAX_OPERATIONS {
            return Err(format!("the program has more than {MAX_OPERATIONS} tokens"));
        }
        let start = self.at;
        if matches!(s[start], b'{' | b'}') {
            self.at += 1;
        } else {
            while self.at < s.len()
                && !s[self.at].is_ascii_whitespace()
                && !matches!(s[self.at], b'{' | b'}' | b'%' | 0)
            {
                self.at += 1;
            }
        }
        Ok(Some(&s[start..self.at]))
    }
}

/// The steps of a block whose `{` has been read, up to its `}`.
fn parse_block(tokens: &mut Tokens, depth: usize) -> Result<Vec<Step>, String> {
    if depth > MAX_NESTING {
        return Err(format!("blocks nest deeper than {MAX_NESTING}"));
    }
    let mut items: Vec<Item> = Vec::new();
    loop {
        let token = tokens
            .next_token()?
            .ok_or("the program ends inside a { } block")?;
        match token {
            b"}" => break,
            b"{" => items.push(Item::Block(parse_block(tokens, depth + 1)?)),
            b"if" => {
                let then = pop_block(&mut items, "if")?;
                items.push(Item::Step(Step::If(then)));
            }
            b"ifelse" => {
                let otherwise = pop_block(&mut items, "ifelse")?;
                let then = pop_block(&mut items, "ifelse")?;
                items.push(Item::Step(Step::IfElse(then, otherwise)));
            }
            word => items.push(Item::Step(parse_word(word)?)),
        }
    }
    items
        .into_iter()
        .map(|item| match item {
            Item::Step(step) => Ok(step),
            Item::Block(_) => Err("a { } block not followed by if or ifelse".to_string()),
        })
        .collect()
}

fn pop_block(items: &mut Vec<Item>, operator: &str) -> Result<Vec<Step>, String> {
    match items.pop() {
        Some(Item::Block(steps)) => Ok(steps),
        _ => Err(format!("{operator} without the {{ }} block it needs")),
    }
}

/// A number, `true`, `false` or an operator.
fn parse_word(word: &[u8]) -> Result<Step, String> {
    let text = std::str::from_utf8(word).map_err(|_| "a token that is not ASCII".to_string())?;
    match text {
        "true" => return Ok(Step::Push(Value::Bool(true))),
        "false" => return Ok(Step::Push(Value::Bool(false))),
        _ => {}
    }
    if let Some(op) = Operator::from_name(text) {
        return Ok(Step::Apply(op));
    }
    let numeric = text
        .bytes()
        .all(|c| c.is_ascii_digit() || matches!(c, b'+' | b'-' | b'.' | b'e' | b'E'));
    if numeric && text.bytes().any(|c| c.is_ascii_digit()) {
        if let Ok(i) = text.parse::<i64>() {
            return Ok(Step::Push(Value::Int(i)));
        }
        if let Ok(r) = text.parse::<f64>() {
            if r.is_finite() {
                return Ok(Step::Push(Value::Real(r)));
            }
        }
    }
    Err(format!("{text} is not an operator of type 4 functions"))
}

fn number(v: Value) -> Result<f64, String> {
    match v {
        Value::Int(i) => Ok(i as f64),
        Value::Real(r) => Ok(r),
        Value::Bool(_) => Err("a boolean where a number is needed".into()),
    }
}

fn integer(v: Value) -> Result<i64, String> {
    match v {
        Value::Int(i) => Ok(i),
        _ => Err("a non-integer where an integer is needed".into()),
    }
}

/// The stack and the count of operations run.
struct Machine {
    stack: Vec<Value>,
    operations: usize,
}

impl Machine {
    fn push(&mut self, v: Value) -> Result<(), String> {
        if self.stack.len() >= MAX_STACK {
            return Err(format!("the stack grows beyond {MAX_STACK} values"));
        }
        if let Value::Real(r) = v {
            if !r.is_finite() {
                return Err("a result that is not a finite number".into());
            }
        }
        self.stack.push(v);
        Ok(())
    }

    fn pop(&mut self) -> Result<Value, String> {
        self.stack
            .pop()
            .ok_or_else(|| "an operator finds the stack empty".to_string())
    }

    fn pop_number(&mut self) -> Result<f64, String> {
        number(self.pop()?)
    }

    fn run(&mut self, steps: &[Step]) -> Result<(), String> {
        for step in steps {
            self.operations += 1;
            if self.operations > MAX_OPERATIONS {
                return Err(format!("more than {MAX_OPERATIONS} operations"));
            }
            match step {
                Step::Push(v) => self.push(*v)?,
                Step::Apply(op) => self.apply(*op)?,
                Step::If(then) => {
                    if self.pop_bool()? {
                        self.run(then)?;
                    }
                }
                Step::IfElse(then, otherwise) => {
                    let branch = if self.pop_bool()? { then } else { otherwise };
                    self.run(branch)?;
                }
            }
        }
        Ok(())
    }

    fn pop_bool(&mut self) -> Result<bool, String> {
        match self.pop()? {
            Value::Bool(b) => Ok(b),
            _ => Err("if or ifelse finds no boolean".into()),
        }
    }

    fn apply(&mut self, op: Operator) -> Result<(), String> {
        use Operator::*;
        match op {
            Abs | Neg | Ceiling | Floor | Round | Truncate | Cvi | Cvr => self.unary_exact(op),
            Sqrt | Sin | Cos | Ln | Log => self.unary_real(op),
            Add | Sub | Mul => self.arithmetic(op),
            Div | Exp | Atan => self.binary_real(op),
            Idiv | Mod | Bitshift => self.binary_integer(op),
            Eq | Ne | Ge | Gt | Le | Lt => self.compare(op),
            And | Or | Xor | Not => self.logic(op),
            Copy | Dup | Exch | Index | Pop | Roll => self.stack_op(op),
        }
    }

    /// Operators that keep an integer an integer.
    fn unary_exact(&mut self, op: Operator) -> Result<(), String> {
        let v = self.pop()?;
        let result = match (op, v) {
            (Operator::Cvr, _) => Value::Real(number(v)?),
            (Operator::Cvi, _) => {
                let r = number(v)?.trunc();
                if r.abs() >= 9.0e18 {
                    return Err("cvi of a number beyond the integers".into());
                }
                Value::Int(r as i64)
            }
            (Operator::Abs, Value::Int(i)) => i
                .checked_abs()
                .map_or(Value::Real((i as f64).abs()), Value::Int),
            (Operator::Neg, Value::Int(i)) => {
                i.checked_neg().map_or(Value::Real(-(i as f64)), Value::Int)
            }
            (_, Value::Int(i)) => Value::Int(i),
            (_, Value::Real(r)) => Value::Real(match op {
                Operator::Abs => r.abs(),
                Operator::Neg => -r,
                Operator::Ceiling => r.ceil(),
                Operator::Floor => r.floor(),
                // PostScript rounds halves up (towards positive infinity).
                Operator::Round => (r + 0.5).floor(),
                _ => r.trunc(),
            }),
            (_, Value::Bool(_)) => return Err("a boolean where a number is needed".into()),
        };
        self.push(result)
    }

    fn unary_real(&mut self, op: Operator) -> Result<(), String> {
        let x = self.pop_number()?;
        let result = match op {
            Operator::Sqrt if x < 0.0 => return Err("sqrt of a negative number".into()),
            Operator::Ln | Operator::Log if x <= 0.0 => {
                return Err("the logarithm of a number that is not positive".into())
            }
            Operator::Sqrt => x.sqrt(),
            Operator::Sin => x.to_radians().sin(),
            Operator::Cos => x.to_radians().cos(),
            Operator::Ln => x.ln(),
            _ => x.log10(),
        };
        self.push(Value::Real(result))
    }

    fn arithmetic(&mut self, op: Operator) -> Result<(), String> {
        let (b, a) = (self.pop()?, self.pop()?);
        if let (Value::Int(x), Value::Int(y)) = (a, b) {
            let exact = match op {
                Operator::Add => x.checked_add(y),
                Operator::Sub => x.checked_sub(y),
                _ => x.checked_mul(y),
            };
            if let Some(v) = exact {
                return self.push(Value::Int(v));
            }
        }
        let (x, y) = (number(a)?, number(b)?);
        let result = match op {
            Operator::Add => x + y,
            Operator::Sub => x - y,
            _ => x * y,
        };
        self.push(Value::Real(result))
    }

    fn binary_real(&mut self, op: Operator) -> Result<(), String> {
        let (y, x) = (self.pop_number()?, self.pop_number()?);
        let result = match op {
            Operator::Div if y == 0.0 => return Err("division by zero".into()),
            Operator::Div => x / y,
            Operator::Exp => x.powf(y),
            // atan: num den -> the angle in degrees, 0 to 360.
            _ if x == 0.0 && y == 0.0 => return Err("atan of 0 and 0".into()),
            _ => x.atan2(y).to_degrees().rem_euclid(360.0),
        };
        self.push(Value::Real(result))
    }

    fn binary_integer(&mut self, op: Operator) -> Result<(), String> {
        let (y, x) = (integer(self.pop()?)?, integer(self.pop()?)?);
        let result = match op {
            Operator::Idiv | Operator::Mod if y == 0 => {
                return Err("integer division by zero".into())
            }
            Operator::Idiv => x.wrapping_div(y),
            Operator::Mod => x.wrapping_rem(y),
            // bitshift: left for a positive shift, right (logically) for a negative one.
            _ if y >= 64 || y <= -64 => 0,
            _ if y >= 0 => x.wrapping_shl(y as u32),
            _ => ((x as u64) >> (-y) as u32) as i64,
        };
        self.push(Value::Int(result))
    }

    fn compare(&mut self, op: Operator) -> Result<(), String> {
        let (b, a) = (self.pop()?, self.pop()?);
        let result = match (a, b) {
            (Value::Bool(x), Value::Bool(y)) => match op {
                Operator::Eq => x == y,
                Operator::Ne => x != y,
                _ => return Err("an ordering of booleans".into()),
            },
            _ => {
                let (x, y) = (number(a)?, number(b)?);
                match op {
                    Operator::Eq => x == y,
                    Operator::Ne => x != y,
                    Operator::Ge => x >= y,
                    Operator::Gt => x > y,
                    Operator::Le => x <= y,
                    _ => x < y,
                }
            }
        };
        self.push(Value::Bool(result))
    }

    fn logic(&mut self, op: Operator) -> Result<(), String> {
        if op == Operator::Not {
            let result = match self.pop()? {
                Value::Bool(b) => Value::Bool(!b),
                Value::Int(i) => Value::Int(!i),
                Value::Real(_) => return Err("not of a real number".into()),
            };
            return self.push(result);
        }
        let (b, a) = (self.pop()?, self.pop()?);
        let result = match (a, b) {
            (Value::Bool(x), Value::Bool(y)) => Value::Bool(match op {
                Operator::And => x & y,
                Operator::Or => x | y,
                _ => x ^ y,
            }),
            (Value::Int(x), Value::Int(y)) => Value::Int(match op {
                Operator::And => x & y,
                Operator::Or => x | y,
                _ => x ^ y,
            }),
            _ => return Err("and, or or xor of mixed or real operands".into()),
        };
        self.push(result)
    }

    fn stack_op(&mut self, op: Operator) -> Result<(), String> {
        match op {
            Operator::Pop => self.pop().map(|_| ()),
            Operator::Dup => {
                let v = *self.stack.last().ok_or("dup finds the stack empty")?;
                self.push(v)
            }
            Operator::Exch => {
                let (b, a) = (self.pop()?, self.pop()?);
                self.push(b)?;
                self.push(a)
            }
            Operator::Index => {
                let n = self.count_operand("index")?;
                let v = *self
                    .stack
                    .iter()
                    .rev()
                    .nth(n)
                    .ok_or("index beyond the stack")?;
                self.push(v)
            }
            Operator::Copy => {
                let n = self.count_operand("copy")?;
                if n > self.stack.len() {
                    return Err("copy of more values than the stack holds".into());
                }
                let top = self.stack[self.stack.len() - n..].to_vec();
                top.into_iter().try_for_each(|v| self.push(v))
            }
            _ => self.roll(),
        }
    }

    /// A non-negative integer operand (of `index` and `copy`).
    fn count_operand(&mut self, operator: &str) -> Result<usize, String> {
        let n = integer(self.pop()?)?;
        usize::try_from(n).map_err(|_| format!("{operator} of a negative count"))
    }

    /// `n j roll`: the top `n` values turned `j` places (towards the top for a positive `j`).
    fn roll(&mut self) -> Result<(), String> {
        let j = integer(self.pop()?)?;
        let n = self.count_operand("roll")?;
        if n > self.stack.len() {
            return Err("roll of more values than the stack holds".into());
        }
        if n > 0 {
            let start = self.stack.len() - n;
            let shift = j.rem_euclid(n as i64) as usize;
            self.stack[start..].rotate_right(shift);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(source: &str, inputs: &[f64], outputs: usize) -> Result<Vec<f64>, String> {
        Program::parse(source.as_bytes())?.run(inputs, outputs)
    }

    #[test]
    fn arithmetic_by_hand() {
        assert_eq!(run("{ 2 mul 1 add }", &[0.25], 1), Ok(vec![1.5]));
        assert_eq!(
            run("{ 7 2 idiv 7 2 mod -7 2 mod }", &[], 3),
            Ok(vec![3.0, 1.0, -1.0])
        );
        assert_eq!(
            run("{ 2 sqrt dup mul }", &[], 1).map(|v| (v[0] - 2.0).abs() < 1e-12),
            Ok(true)
        );
        assert_eq!(
            run("{ 1 1 atan 0 1 atan -1 0 atan }", &[], 3),
            Ok(vec![45.0, 0.0, 270.0])
        );
        assert_eq!(
            run("{ 30 sin 60 cos 100 log 2 3 exp }", &[], 4)
                .map(|v| v.iter().map(|x| (x * 1e9).round() / 1e9).collect()),
            Ok(vec![0.5, 0.5, 2.0, 8.0])
        );
        assert_eq!(
            run(
                "{ -2.5 round 2.5 round -2.7 truncate 2.2 ceiling -2.2 floor }",
                &[],
                5
            ),
            Ok(vec![-2.0, 3.0, -2.0, 3.0, -3.0])
        );
        assert_eq!(
            run("{ 3.9 cvi -3.9 cvi 1 cvr 4 neg -3 abs }", &[], 5),
            Ok(vec![3.0, -3.0, 1.0, -4.0, 3.0])
        );
        assert_eq!(
            run(
                "{ 1 3 bitshift 16 -2 bitshift 12 10 and 12 10 or 12 10 xor }",
                &[],
                5
            ),
            Ok(vec![8.0, 4.0, 8.0, 14.0, 6.0])
        );
    }

    #[test]
    fn stack_operators_by_hand() {
        assert_eq!(run("{ 1 2 3 3 1 roll }", &[], 3), Ok(vec![3.0, 1.0, 2.0]));
        assert_eq!(run("{ 1 2 3 3 -1 roll }", &[], 3), Ok(vec![2.0, 3.0, 1.0]));
        assert_eq!(run("{ 1 2 2 copy }", &[], 4), Ok(vec![1.0, 2.0, 1.0, 2.0]));
        assert_eq!(
            run("{ 5 6 7 2 index exch pop }", &[], 3),
            Ok(vec![5.0, 6.0, 5.0])
        );
        assert_eq!(run("{ 4 dup pop 9 exch }", &[], 2), Ok(vec![9.0, 4.0]));
    }

    #[test]
    fn conditionals_choose_their_branch() {
        let program = "{ dup 0.5 lt { 2 mul } { 1 exch sub 2 mul } ifelse }";
        assert_eq!(run(program, &[0.25], 1), Ok(vec![0.5]));
        assert_eq!(run(program, &[0.75], 1), Ok(vec![0.5]));
        let nested = "{ dup 0.5 gt { pop 1 } if  true false ne { 10 add } if }";
        assert_eq!(run(nested, &[0.25], 1), Ok(vec![10.25]));
        assert_eq!(run(nested, &[0.75], 1), Ok(vec![11.0]));
        assert!(
            run("{ 1 2 eq 3 3 ge not }", &[], 2).is_err(),
            "booleans are not numbers"
        );
    }

    #[test]
    fn bad_programs_are_refused_with_a_reason() {
        let cases = [
            ("", "empty"),
            ("1 2 add", "start with {"),
            ("{ 1 2 add", "ends inside"),
            ("{ 1 2 add } 3", "after the program"),
            ("{ 1 moveto }", "moveto is not an operator"),
            ("{ { 1 } }", "not followed by if"),
            ("{ 1 if }", "if without"),
        ];
        for (source, reason) in cases {
            let e = Program::parse(source.as_bytes()).unwrap_err();
            assert!(e.contains(reason), "{source}: {e}");
        }
        let deep = format!("{}{}", "{ true ".repeat(70), "} if ".repeat(70));
        assert!(Program::parse(deep.as_bytes())
            .unwrap_err()
            .contains("nest"));
    }

    #[test]
    fn running_errors_are_reported_not_panics() {
        let cases = [
            ("{ add }", "stack empty"),
            ("{ 1 0 div }", "division by zero"),
            ("{ 1 0 idiv }", "division by zero"),
            ("{ -1 sqrt }", "negative"),
            ("{ 0 ln }", "not positive"),
            ("{ 1 5 index }", "beyond the stack"),
            ("{ 1 -1 copy }", "negative count"),
            ("{ 1.5 2 idiv }", "integer"),
            ("{ 1 true add }", "boolean"),
            ("{ 1 }", "leaves 1 value"),
            ("{ 10 1000 exp 1000 exp }", "not a finite"),
            (
                "{ 9223372036854775807 1 add 1e300 mul 1e300 mul }",
                "not a finite",
            ),
        ];
        for (source, reason) in cases {
            let e = run(source, &[], 2).unwrap_err();
            assert!(e.contains(reason), "{source}: {e}");
        }
        let grows = format!("{{ {} }}", "1 ".repeat(101));
        assert!(run(&grows, &[], 1).unwrap_err().contains("beyond 100"));
        assert_eq!(
            run("{ 9223372036854775807 1 add }", &[], 1),
            Ok(vec![9223372036854775808.0])
        );
    }
}
