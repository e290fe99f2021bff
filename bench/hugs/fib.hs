-- doubly recursive fib 25: calls and arithmetic, no lists
fib :: Integer -> Integer
fib n = if n < 2 then n else fib (n - 1) + fib (n - 2)
main = print (fib 25)
