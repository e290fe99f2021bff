-- the sum of a list comprehension with a guard
main = print (sum [x * x | x <- [1 .. 300000], x `mod` 3 == 1])
